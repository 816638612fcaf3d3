#pragma once
/// @file tcp_load.hpp
/// The daemon benchmark's Modbus TCP load: blocking loopback clients (one request
/// outstanding each, TCP_NODELAY), each a thread reading a load shape back to back or
/// writing at a random pace, and the figures of a window of them.
#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "load_shape.hpp"

namespace fieldbridge::bench {

/// What a client reads: the shape's n-th read, to unit first_unit + its device.
struct Target {
    LoadShape shape{LoadShape::Kind::xeg};
    std::uint8_t first_unit = 1;
};

/// What one client saw.
struct ClientResult {
    std::vector<double> latency_us;  ///< requests sent inside the window
    std::uint64_t errors = 0;        ///< exceptions, short reads, timeouts
    std::array<std::uint64_t, 256> exceptions{};  ///< exception replies by code
    std::string failure;             ///< why the client stopped early, if it did
};

/// What the clients of one window saw together.
struct LoadFigures {
    double seconds = 0.0;
    std::uint64_t reads = 0;
    std::uint64_t errors = 0;
    std::string exceptions;  ///< "0x0B x 12, ..." or empty
    double p50_us = 0.0;
    double p99_us = 0.0;
    double max_us = 0.0;
    std::string failures;
};

/// One Modbus TCP client: the reads of @p target from its @p first -th on, one at a
/// time, back to back, until @p stop; latencies recorded for requests sent in
/// [window_start, window_end). Runs at nice 10 (it stands for another machine).
void run_client(std::uint16_t port, Target target, std::uint64_t first, const std::atomic<bool>& stop,
                std::chrono::steady_clock::time_point window_start, std::chrono::steady_clock::time_point window_end,
                ClientResult& result);

/// The writer of part (3): FC06 to @p address of @p unit every 30-50 ms at a random
/// phase, @p count times, at the default priority (the daemon's PLC); latencies of the
/// writes answered with their echo, in microseconds.
[[nodiscard]] ClientResult run_writer(std::uint16_t port, std::uint8_t unit, std::uint16_t address, int count);

/// Runs @p clients back-to-back clients for warm-up + @p seconds; @p in_window runs on
/// this thread at the window's start (true) and end (false): simulator counters,
/// daemon CPU.
[[nodiscard]] LoadFigures run_load(std::uint16_t port, Target target, unsigned clients, double seconds,
                                   const std::function<void(bool)>& in_window);

}  // namespace fieldbridge::bench
