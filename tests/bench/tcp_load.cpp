#include "tcp_load.hpp"

#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <random>
#include <span>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>

#include "loopback_port.hpp"
#include "percentile.hpp"

namespace fieldbridge::bench {

namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::duration;
using std::chrono::milliseconds;

bool read_exactly(int fd, std::uint8_t* data, std::size_t size) {
    std::size_t got = 0;
    while (got < size) {
        const auto n = recv(fd, data + got, size - got, 0);
        if (n <= 0) return false;
        got += static_cast<std::size_t>(n);
    }
    return true;
}

/// A client connection for the load (loopback_port.hpp) with a 3 s receive timeout, so
/// that a lost answer ends the client, not the run; an empty one, with @p failure saying
/// why, when it cannot connect.
test_support::UniqueFd connect_client(std::uint16_t port, std::string& failure) {
    try {
        test_support::UniqueFd fd = connect_loopback(port);
        const timeval timeout{3, 0};
        setsockopt(fd.get(), SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
        return fd;
    } catch (const std::runtime_error& error) {
        failure = error.what();
        return test_support::UniqueFd{};
    }
}

/// Sends @p request (a whole MBAP frame) and reads the answer's MBAP header and PDU
/// into @p reply; returns the PDU length (function code onwards), or 0 with
/// @p failure saying why.
std::size_t exchange(int fd, std::span<const std::uint8_t> request, std::array<std::uint8_t, 260>& reply,
                     std::string& failure) {
    if (send(fd, request.data(), request.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(request.size())) {
        failure = "send failed";
        return 0;
    }
    if (!read_exactly(fd, reply.data(), 7)) {
        failure = "no answer within 3 s";
        return 0;
    }
    const std::size_t rest = static_cast<std::size_t>((reply[4] << 8) | reply[5]) - 1;
    if (rest == 0 || rest > 253 || !read_exactly(fd, reply.data() + 7, rest)) {
        failure = "bad MBAP length";
        return 0;
    }
    return rest;
}

}  // namespace

void run_client(std::uint16_t port, Target target, std::uint64_t first, const std::atomic<bool>& stop,
                Clock::time_point window_start, Clock::time_point window_end, ClientResult& result) {
    // Linux: a thread's nice value is its own (setpriority on the thread id).
    static_cast<void>(setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), 10));
    const test_support::UniqueFd fd = connect_client(port, result.failure);
    if (fd.get() < 0) return;
    result.latency_us.reserve(400'000);
    std::uint16_t transaction = 0;
    for (std::uint64_t n = first; !stop.load(std::memory_order_relaxed); ++n) {
        ++transaction;
        const bench::ShapeRead read = target.shape.read(n);
        const std::array<std::uint8_t, 12> request{
            static_cast<std::uint8_t>(transaction >> 8), static_cast<std::uint8_t>(transaction & 0xFF), 0, 0, 0, 6,
            static_cast<std::uint8_t>(target.first_unit + read.device), read.function,
            static_cast<std::uint8_t>(read.address >> 8), static_cast<std::uint8_t>(read.address & 0xFF),
            static_cast<std::uint8_t>(read.count >> 8), static_cast<std::uint8_t>(read.count & 0xFF)};
        const Clock::time_point sent = Clock::now();
        std::array<std::uint8_t, 260> reply{};
        const std::size_t rest = exchange(fd.get(), request, reply, result.failure);
        if (rest == 0) break;
        const auto answered = Clock::now();
        const bool ok = reply[7] == read.function && rest == std::size_t{2} + 2u * read.count;
        if (!ok) ++result.errors;
        if (reply[7] == (read.function | 0x80) && rest == 2) ++result.exceptions[reply[8]];
        if (ok && sent >= window_start && sent < window_end) {
            result.latency_us.push_back(duration<double, std::micro>(answered - sent).count());
        }
    }
}

ClientResult run_writer(std::uint16_t port, std::uint8_t unit, std::uint16_t address, int count) {
    ClientResult result;
    const test_support::UniqueFd fd = connect_client(port, result.failure);
    if (fd.get() < 0) return result;
    std::mt19937 random(20261125);
    std::uniform_int_distribution<int> gap_us(30'000, 50'000);
    for (int i = 0; i < count; ++i) {
        std::this_thread::sleep_for(std::chrono::microseconds{gap_us(random)});
        const auto value = static_cast<std::uint16_t>(1000 + (i % 2));
        const auto transaction = static_cast<std::uint16_t>(i + 1);
        const std::array<std::uint8_t, 12> request{
            static_cast<std::uint8_t>(transaction >> 8), static_cast<std::uint8_t>(transaction & 0xFF), 0, 0, 0, 6, unit,
            0x06, static_cast<std::uint8_t>(address >> 8), static_cast<std::uint8_t>(address & 0xFF),
            static_cast<std::uint8_t>(value >> 8), static_cast<std::uint8_t>(value & 0xFF)};
        const auto sent = Clock::now();
        std::array<std::uint8_t, 260> reply{};
        const std::size_t rest = exchange(fd.get(), request, reply, result.failure);
        if (rest == 0) break;
        const auto answered = Clock::now();
        // FC06 answers with the request's PDU echoed.
        if (rest == 5 && std::equal(request.begin() + 7, request.end(), reply.begin() + 7)) {
            result.latency_us.push_back(duration<double, std::micro>(answered - sent).count());
        } else {
            ++result.errors;
            if (reply[7] == 0x86 && rest == 2) ++result.exceptions[reply[8]];
        }
    }
    return result;
}

LoadFigures run_load(std::uint16_t port, Target target, unsigned clients, double seconds,
                     const std::function<void(bool)>& in_window) {
    std::atomic<bool> stop{false};
    const auto start = Clock::now() + milliseconds{100};  // every client connected
    const auto window_start = start + milliseconds{400};
    const auto window_end = window_start + std::chrono::duration_cast<Clock::duration>(duration<double>(seconds));
    std::vector<ClientResult> results(clients);
    std::vector<std::thread> threads;
    for (unsigned i = 0; i < clients; ++i) {
        // Clients start at different points of the shape's sequence (other devices,
        // other addresses).
        threads.emplace_back(run_client, port, target, std::uint64_t{i} * 7, std::cref(stop), window_start,
                             window_end, std::ref(results[i]));
    }
    std::this_thread::sleep_until(window_start);
    in_window(true);
    std::this_thread::sleep_until(window_end);
    in_window(false);
    stop = true;
    for (auto& thread : threads) thread.join();

    LoadFigures figures;
    figures.seconds = seconds;
    std::vector<double> all;
    std::array<std::uint64_t, 256> exceptions{};
    for (const auto& result : results) {
        all.insert(all.end(), result.latency_us.begin(), result.latency_us.end());
        figures.errors += result.errors;
        for (std::size_t code = 0; code < exceptions.size(); ++code) exceptions[code] += result.exceptions[code];
        if (!result.failure.empty()) figures.failures += result.failure + "; ";
    }
    for (std::size_t code = 0; code < exceptions.size(); ++code) {
        if (exceptions[code] == 0) continue;
        if (!figures.exceptions.empty()) figures.exceptions += ", ";
        figures.exceptions += fmt::format("0x{:02X} x {}", code, exceptions[code]);
    }
    const Spread latency = spread_of(std::move(all));
    figures.reads = latency.count;
    figures.p50_us = latency.p50;
    figures.p99_us = latency.p99;
    figures.max_us = latency.max;
    return figures;
}

}  // namespace fieldbridge::bench
