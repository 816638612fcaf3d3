#include "metrics_scraper.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>

namespace fieldbridge::bench {

namespace {

using Clock = std::chrono::steady_clock;

/// One scrape; the answer, or empty with @p error set.
std::string scrape_once(std::uint16_t port, std::string& error) {
    const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0) {
        error = std::string("socket: ") + std::strerror(errno);
        return {};
    }
    timeval timeout{2, 0};
    ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(port);
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    std::string answer;
    if (::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
        error = std::string("connect: ") + std::strerror(errno);
    } else {
        const std::string request = "GET /metrics HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n";
        if (::send(fd, request.data(), request.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(request.size())) {
            error = std::string("send: ") + std::strerror(errno);
        }
        std::array<char, 16384> buffer{};
        while (error.empty()) {
            const auto n = ::recv(fd, buffer.data(), buffer.size(), 0);
            if (n == 0) break;
            if (n < 0) {
                error = std::string("recv: ") + std::strerror(errno);
                break;
            }
            answer.append(buffer.data(), static_cast<std::size_t>(n));
        }
    }
    ::close(fd);
    if (error.empty() && answer.rfind("HTTP/1.1 200", 0) != 0) error = "not 200: " + answer.substr(0, 40);
    return error.empty() ? answer : std::string();
}

}  // namespace

MetricsScraper::MetricsScraper(std::uint16_t port, std::chrono::milliseconds period)
    : port_(port), period_(period), thread_([this] { run(); }) {}

MetricsScraper::~MetricsScraper() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
}

ScrapeFigures MetricsScraper::stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
    std::sort(figures_.latency_us.begin(), figures_.latency_us.end());
    return figures_;
}

void MetricsScraper::run() {
    auto next = Clock::now();
    while (!stop_) {
        std::string error;
        const auto started = Clock::now();
        const std::string answer = scrape_once(port_, error);
        if (error.empty()) {
            ++figures_.ok;
            figures_.last_bytes = answer.size();
            figures_.latency_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - started).count());
        } else {
            ++figures_.failed;
            if (figures_.failure.empty()) figures_.failure = error;
        }
        next += period_;
        std::this_thread::sleep_until(next);
    }
}

}  // namespace fieldbridge::bench
