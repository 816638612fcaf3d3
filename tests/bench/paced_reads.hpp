#pragma once
/// @file paced_reads.hpp
/// The paced Modbus TCP load generator of item 5 of issue 14: one thread, one epoll
/// set, @c connections non-blocking loopback connections, each sending its next read
/// when it is due (connection i every connections / rate seconds, the connections
/// evenly out of phase), one request outstanding per connection. Latency counts from
/// when a request was *due*: an answer that comes late delays the next request of
/// its connection, and that wait is latency too (no coordinated omission). One
/// thread, so that on a two-core machine the generator takes one core at most and
/// leaves the other to the server it measures (the 32 threads it replaces could not
/// pace next to the daemon).
#include <chrono>
#include <cstdint>
#include <string>

namespace fieldbridge::bench {

struct PacedLoad {
    std::uint16_t port = 0;
    std::uint8_t unit = 1;
    std::uint8_t function = 0x04;
    std::uint16_t address = 0x0300;
    std::uint16_t count = 2;
    unsigned connections = 32;
    double rate = 50'000.0;  ///< requests per second, all connections together
    std::chrono::duration<double> warm_up{0.4};
    std::chrono::duration<double> window{5.0};  ///< requests due in it are counted
};

struct PacedFigures {
    std::uint64_t reads = 0;   ///< answered reads due in the window
    std::uint64_t errors = 0;  ///< answers that were not the read's
    double seconds = 0.0;
    double p50_us = 0.0;  ///< from when due
    double p99_us = 0.0;
    double max_us = 0.0;
    double service_p99_us = 0.0;  ///< from when the request actually went
    /// Requests that went later than 100 us after they were due (the generator or
    /// the server behind).
    std::uint64_t late_sends = 0;
    /// Requests due in the window still unanswered 100 ms after it (not in the
    /// percentiles: a figure above 0 means the percentiles flatter the server).
    std::uint64_t unanswered = 0;
    std::string failure;  ///< empty, or why the run stopped early
};

/// Runs @p load on this thread. Throws std::runtime_error when it cannot connect.
[[nodiscard]] PacedFigures run_paced_reads(const PacedLoad& load);

}  // namespace fieldbridge::bench
