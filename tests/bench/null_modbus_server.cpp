#include "null_modbus_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace fieldbridge::bench {
namespace {

constexpr std::uint64_t stop_key = ~std::uint64_t{0};
constexpr std::uint64_t listen_key = stop_key - 1;

/// The answer to one complete request frame @p frame (MBAP + PDU), appended to @p out.
void answer(const std::uint8_t* frame, std::size_t size, std::vector<std::uint8_t>& out) {
    const std::uint8_t function = size > 7 ? frame[7] : 0;
    const bool read = (function == 0x03 || function == 0x04) && size == 12;
    const std::size_t count = read ? ((std::size_t{frame[10]} << 8) | frame[11]) : 0;
    std::vector<std::uint8_t> pdu;
    if (read && count >= 1 && count <= 125) {
        pdu.assign(2 + 2 * count, 0);
        pdu[0] = function;
        pdu[1] = static_cast<std::uint8_t>(2 * count);
    } else {
        pdu = {static_cast<std::uint8_t>(function | 0x80), 0x01};
    }
    const std::size_t length = pdu.size() + 1;
    out.insert(out.end(), {frame[0], frame[1], 0, 0, static_cast<std::uint8_t>(length >> 8),
                           static_cast<std::uint8_t>(length & 0xFF), frame[6]});
    out.insert(out.end(), pdu.begin(), pdu.end());
}

}  // namespace

NullModbusServer::NullModbusServer() {
    listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    stop_fd_ = ::eventfd(0, EFD_CLOEXEC);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t length = sizeof address;
    if (listen_fd_ < 0 || stop_fd_ < 0 || ::bind(listen_fd_, reinterpret_cast<sockaddr*>(&address), length) != 0 ||
        ::listen(listen_fd_, 128) != 0 ||
        ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
        const std::string why = std::strerror(errno);
        if (listen_fd_ >= 0) ::close(listen_fd_);
        if (stop_fd_ >= 0) ::close(stop_fd_);
        throw std::runtime_error("null Modbus TCP server: cannot listen on loopback: " + why);
    }
    port_ = ntohs(address.sin_port);
    thread_ = std::thread([this] { serve(); });
}

NullModbusServer::~NullModbusServer() {
    const std::uint64_t one = 1;
    static_cast<void>(::write(stop_fd_, &one, sizeof one));
    thread_.join();
    ::close(listen_fd_);
    ::close(stop_fd_);
}

void NullModbusServer::serve() {
    const int epoll = ::epoll_create1(EPOLL_CLOEXEC);
    epoll_event event{};
    event.events = EPOLLIN;
    event.data.u64 = stop_key;
    ::epoll_ctl(epoll, EPOLL_CTL_ADD, stop_fd_, &event);
    event.data.u64 = listen_key;
    ::epoll_ctl(epoll, EPOLL_CTL_ADD, listen_fd_, &event);
    std::map<int, std::vector<std::uint8_t>> pending;  // bytes received, per connection
    std::array<epoll_event, 64> events{};
    std::array<std::uint8_t, 4096> buffer{};
    std::vector<std::uint8_t> out;
    bool running = true;
    while (running) {
        const int ready = ::epoll_wait(epoll, events.data(), static_cast<int>(events.size()), -1);
        for (int e = 0; e < ready; ++e) {
            const std::uint64_t key = events[static_cast<std::size_t>(e)].data.u64;
            if (key == stop_key) {
                running = false;
            } else if (key == listen_key) {
                const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
                if (fd < 0) continue;
                const int one = 1;
                ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
                epoll_event client{};
                client.events = EPOLLIN;
                client.data.u64 = static_cast<std::uint64_t>(fd);
                ::epoll_ctl(epoll, EPOLL_CTL_ADD, fd, &client);
                pending[fd];
            } else {
                const auto fd = static_cast<int>(key);
                const ssize_t n = ::recv(fd, buffer.data(), buffer.size(), 0);
                if (n <= 0) {
                    if (n < 0 && errno == EAGAIN) continue;
                    ::close(fd);
                    pending.erase(fd);
                    continue;
                }
                auto& in = pending[fd];
                in.insert(in.end(), buffer.begin(), buffer.begin() + n);
                out.clear();
                std::size_t used = 0;
                while (in.size() - used >= 7) {
                    const std::size_t frame = 6 + ((std::size_t{in[used + 4]} << 8) | in[used + 5]);
                    if (in.size() - used < frame) break;
                    answer(in.data() + used, frame, out);
                    used += frame;
                }
                in.erase(in.begin(), in.begin() + static_cast<std::ptrdiff_t>(used));
                if (!out.empty()) static_cast<void>(::send(fd, out.data(), out.size(), MSG_NOSIGNAL));
            }
        }
    }
    for (const auto& [fd, bytes] : pending) ::close(fd);
    ::close(epoll);
}

}  // namespace fieldbridge::bench
