#pragma once
/// @file floor_pairs.hpp
/// The gateway measured against the floor in alternating windows (issue 14): a floor
/// window (raw_master.hpp) and, right after it, a gateway window of the same length
/// on the same simulator make a pair; every ratio is taken within its pair, and the
/// figures a line benchmark reports are the medians over its pairs. This machine's
/// CPU cost per wake-up moves twofold from minute to minute, so only windows measured
/// seconds apart can be divided by each other.
#include <cstddef>
#include <vector>

namespace fieldbridge::bench {

/// What one window achieved.
struct WindowFigures {
    double tps = 0.0;     ///< transactions per second
    double cpu_us = 0.0;  ///< CPU (user + kernel) per transaction, microseconds
};

struct FloorPair {
    WindowFigures floor;
    WindowFigures gateway;
    /// The gateway's rate over the floor's; 0 when the floor's is 0.
    [[nodiscard]] double rate_ratio() const noexcept;
    /// The gateway's CPU per transaction over the floor's; 0 when the floor's is 0.
    [[nodiscard]] double cpu_ratio() const noexcept;
};

/// What one client, one request outstanding, can reach against the floor whatever the
/// gateway does: after each answer the line waits for that client's next request, so
/// it idles for whatever of the TCP round trip (answer sent -> client wakes -> next
/// request received) the silence does not cover. With the floor's period P = 1 /
/// @p floor_tps, a round trip of @p round_trip_us and the floor's silence of
/// @p silence_us: P / (P + max(0, round trip - silence)). 0 when floor_tps is 0.
[[nodiscard]] double closed_loop_ceiling(double floor_tps, double round_trip_us, double silence_us) noexcept;

/// The pairs of one load, in the order they were measured.
class FloorPairs {
public:
    /// Records @p pair and prints it on stdout: "<bench> pair <n>: floor <tx/s>,
    /// <us/tx>; <gateway> <tx/s>, <us/tx>; ratios rate <r>, CPU <c>".
    void add(const char* bench, const char* gateway, const FloorPair& pair);

    [[nodiscard]] std::size_t size() const noexcept { return pairs_.size(); }
    /// The medians of the pairs' ratios (0 without pairs).
    [[nodiscard]] double median_rate_ratio() const;
    [[nodiscard]] double median_cpu_ratio() const;
    /// Each figure's median over the floor windows, and over the gateway windows.
    [[nodiscard]] WindowFigures median_floor() const;
    [[nodiscard]] WindowFigures median_gateway() const;

private:
    std::vector<FloorPair> pairs_;
};

}  // namespace fieldbridge::bench
