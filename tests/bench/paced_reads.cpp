#include "paced_reads.hpp"

#include "loopback_port.hpp"
#include "percentile.hpp"
#include "unique_fd.hpp"

#include <sys/epoll.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <vector>

namespace fieldbridge::bench {
namespace {

using Clock = std::chrono::steady_clock;

/// Owns a file descriptor.
using Fd = test_support::UniqueFd;

struct Connection {
    Fd fd;
    Clock::time_point next_due;
    bool outstanding = false;
    Clock::time_point due;   ///< of the request outstanding
    Clock::time_point went;
    std::uint16_t transaction = 0;
    std::array<std::uint8_t, 260> rx{};
    std::size_t rx_size = 0;
};

timespec timeout_of(Clock::duration d) {
    const auto ns = std::max<std::int64_t>(0, std::chrono::duration_cast<std::chrono::nanoseconds>(d).count());
    return timespec{static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
}

}  // namespace

PacedFigures run_paced_reads(const PacedLoad& load) {
    // Wake-ups at the due time, not 50 us after it (the default timer slack).
    ::prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
    const Fd epoll(::epoll_create1(EPOLL_CLOEXEC));
    std::vector<Connection> connections;
    connections.reserve(load.connections);
    for (unsigned i = 0; i < load.connections; ++i) {
        connections.push_back(Connection{connect_loopback(load.port), {}, false, {}, {}, 0, {}, 0});
        epoll_event event{};
        event.events = EPOLLIN;
        event.data.u32 = i;
        ::epoll_ctl(epoll.get(), EPOLL_CTL_ADD, connections.back().fd.get(), &event);
    }
    const auto interval = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(static_cast<double>(load.connections) / load.rate));
    const auto start = Clock::now() + std::chrono::milliseconds{10};
    const auto window_start = start + std::chrono::duration_cast<Clock::duration>(load.warm_up);
    const auto window_end = window_start + std::chrono::duration_cast<Clock::duration>(load.window);
    for (unsigned i = 0; i < load.connections; ++i) connections[i].next_due = start + interval * i / load.connections;

    PacedFigures figures;
    figures.seconds = load.window.count();
    std::vector<double> latency;
    std::vector<double> service;
    latency.reserve(static_cast<std::size_t>(load.rate * load.window.count() * 1.1));
    service.reserve(latency.capacity());
    std::array<epoll_event, 64> events{};
    const auto expected_pdu = static_cast<std::size_t>(2 + 2 * load.count);  // function, byte count, registers

    const auto send_due = [&](Clock::time_point now) {
        Clock::time_point earliest = Clock::time_point::max();
        for (auto& c : connections) {
            if (!c.outstanding && c.next_due <= now) {
                ++c.transaction;
                const std::array<std::uint8_t, 12> request{
                    static_cast<std::uint8_t>(c.transaction >> 8), static_cast<std::uint8_t>(c.transaction & 0xFF),
                    0, 0, 0, 6, load.unit, load.function, static_cast<std::uint8_t>(load.address >> 8),
                    static_cast<std::uint8_t>(load.address & 0xFF), static_cast<std::uint8_t>(load.count >> 8),
                    static_cast<std::uint8_t>(load.count & 0xFF)};
                if (::send(c.fd.get(), request.data(), request.size(), MSG_NOSIGNAL) !=
                    static_cast<ssize_t>(request.size())) {
                    figures.failure = "send failed";
                    return earliest;
                }
                c.outstanding = true;
                c.due = c.next_due;
                c.went = now;
                if (now - c.due > std::chrono::microseconds{100} && c.due >= window_start && c.due < window_end) {
                    ++figures.late_sends;
                }
                c.next_due += interval;
            }
            if (!c.outstanding) earliest = std::min(earliest, c.next_due);
        }
        return earliest;
    };

    Clock::time_point now = Clock::now();
    while (now < window_end + std::chrono::milliseconds{100} && figures.failure.empty()) {
        const Clock::time_point earliest = send_due(now);
        if (!figures.failure.empty()) break;
        const auto wait = earliest == Clock::time_point::max() ? std::chrono::milliseconds{100}
                                                               : std::min<Clock::duration>(
                                                                     earliest - Clock::now(), std::chrono::milliseconds{100});
        const timespec timeout = timeout_of(wait);
        const int ready = ::epoll_pwait2(epoll.get(), events.data(), static_cast<int>(events.size()), &timeout, nullptr);
        if (ready < 0 && errno != EINTR) {
            figures.failure = std::string("epoll_pwait2: ") + std::strerror(errno);
            break;
        }
        now = Clock::now();
        for (int e = 0; e < ready; ++e) {
            Connection& c = connections[events[static_cast<std::size_t>(e)].data.u32];
            const ssize_t n = ::recv(c.fd.get(), c.rx.data() + c.rx_size, c.rx.size() - c.rx_size, MSG_DONTWAIT);
            if (n <= 0) {
                if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
                figures.failure = "connection closed by the server";
                break;
            }
            c.rx_size += static_cast<std::size_t>(n);
            if (c.rx_size < 7) continue;
            const std::size_t frame = 6 + ((std::size_t{c.rx[4]} << 8) | c.rx[5]);
            if (frame > c.rx.size() || frame < 8) {
                figures.failure = "bad MBAP length";
                break;
            }
            if (c.rx_size < frame) continue;
            const bool ok = c.rx[7] == load.function && frame - 7 == expected_pdu &&
                            c.rx[0] == (c.transaction >> 8) && c.rx[1] == (c.transaction & 0xFF);
            if (c.outstanding && c.due >= window_start && c.due < window_end) {
                if (ok) {
                    latency.push_back(std::chrono::duration<double, std::micro>(now - c.due).count());
                    service.push_back(std::chrono::duration<double, std::micro>(now - c.went).count());
                } else {
                    ++figures.errors;
                }
            }
            c.outstanding = false;
            std::copy(c.rx.begin() + static_cast<std::ptrdiff_t>(frame),
                      c.rx.begin() + static_cast<std::ptrdiff_t>(c.rx_size), c.rx.begin());
            c.rx_size -= frame;
        }
    }
    for (const auto& c : connections) {
        if (c.outstanding && c.due >= window_start && c.due < window_end) ++figures.unanswered;
    }
    std::sort(latency.begin(), latency.end());
    std::sort(service.begin(), service.end());
    figures.reads = latency.size();
    figures.p50_us = percentile_of_sorted(latency, 0.50);
    figures.p99_us = percentile_of_sorted(latency, 0.99);
    figures.max_us = latency.empty() ? 0.0 : latency.back();
    figures.service_p99_us = percentile_of_sorted(service, 0.99);
    return figures;
}

}  // namespace fieldbridge::bench
