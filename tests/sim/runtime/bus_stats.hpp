#pragma once
/// @file bus_stats.hpp
/// Counters of one simulated bus and of each device on it, as reported by the
/// control socket's `stats` and the --stats-file.

#include <chrono>
#include <cstdint>

#include <nlohmann/json.hpp>

namespace fieldbridge::sim::runtime {

struct DeviceCounters {
    std::uint64_t frames = 0;            ///< frames addressed to the device's own address
    std::uint64_t replies = 0;           ///< replies the model produced (before faults)
    std::uint64_t ignored_dead = 0;      ///< frames for it while it was dead
    std::uint64_t dropped = 0;           ///< replies removed by `drop`
    std::uint64_t corrupted = 0;         ///< replies with a damaged CRC
    std::uint64_t truncated = 0;         ///< replies cut in half
    std::uint64_t delayed = 0;           ///< replies sent late by `delay`
    std::uint64_t garbage_injected = 0;  ///< replies with random bytes in front
};

/// Achieved accuracy of the emulated wire: how late each write left compared with
/// the moment the emulated line would have delivered it. Never early by design.
struct TimingCounters {
    std::uint64_t writes = 0;
    std::chrono::nanoseconds late_sum{};
    std::chrono::nanoseconds late_max{};
    std::uint64_t late_over_100us = 0;
    std::uint64_t late_over_1ms = 0;

    void record(std::chrono::nanoseconds late) noexcept {
        ++writes;
        late_sum += late;
        if (late > late_max) {
            late_max = late;
        }
        if (late > std::chrono::microseconds(100)) {
            ++late_over_100us;
        }
        if (late > std::chrono::milliseconds(1)) {
            ++late_over_1ms;
        }
    }
};

struct WireCounters {
    std::uint64_t requests = 0;          ///< well-formed request frames seen on the bus
    std::uint64_t broadcasts = 0;        ///< of which to a broadcast address
    std::uint64_t unanswered = 0;        ///< addressed frames no device answered
    std::uint64_t replies = 0;           ///< reply writes (after faults)
    std::uint64_t bytes_in = 0;          ///< bytes received from the master
    std::uint64_t bytes_out = 0;         ///< bytes written to the master (replies, echo)
    std::chrono::nanoseconds busy{};     ///< emulated wire time of requests and replies
    std::uint64_t gap_violations = 0;    ///< requests started before the 3.5-char silence
    std::chrono::nanoseconds min_silence{-1};  ///< shortest silence before a request (-1: none)
    std::uint64_t garbage_bytes = 0;     ///< bytes skipped because no frame starts there
    std::uint64_t crc_errors = 0;        ///< frames dropped for a bad CRC
    std::uint64_t collisions = 0;        ///< bursts that arrived while a reply was pending
    std::uint64_t collision_bytes = 0;
    std::uint64_t echoes = 0;            ///< frames echoed by the `echo` fault
    std::uint64_t dropped = 0;           ///< replies removed by faults (all devices)
    std::uint64_t tx_overflow_bytes = 0; ///< bytes the pty would not take (nobody reading)
    std::uint64_t unplugs = 0;
    TimingCounters timing;
};

[[nodiscard]] nlohmann::json to_json(const DeviceCounters& counters);
[[nodiscard]] nlohmann::json to_json(const WireCounters& counters);

}  // namespace fieldbridge::sim::runtime
