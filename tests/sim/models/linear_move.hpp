#pragma once
/// @file linear_move.hpp
/// A straight move at constant speed, evaluated at any simulated time point. All the
/// models move this way (no acceleration ramps): position is an integer in the
/// device's own unit (0.01 mm, encoder counts, pulses).

#include <cstdint>

#include "models/bus_device.hpp"

namespace fieldbridge::sim {

class LinearMove {
public:
    /// A move from @p from to @p to starting at @p start, at @p units_per_second (> 0;
    /// 0 or less is treated as 1 unit a second so that every move ends).
    LinearMove(Clock::time_point start, std::int64_t from, std::int64_t to,
               std::int64_t units_per_second) noexcept;

    [[nodiscard]] std::int64_t position_at(Clock::time_point t) const noexcept;
    [[nodiscard]] bool done_at(Clock::time_point t) const noexcept { return t >= end_; }
    /// The time point at which the move reaches its target.
    [[nodiscard]] Clock::time_point end() const noexcept { return end_; }
    [[nodiscard]] Clock::time_point start() const noexcept { return start_; }
    [[nodiscard]] std::int64_t from() const noexcept { return from_; }
    [[nodiscard]] std::int64_t to() const noexcept { return to_; }
    [[nodiscard]] std::int64_t speed() const noexcept { return speed_; }

private:
    Clock::time_point start_;
    std::int64_t from_;
    std::int64_t to_;
    std::int64_t speed_;
    Clock::time_point end_;
};

/// Distance covered in @p elapsed at @p units_per_second, rounded down, without
/// overflow for any elapsed time below ~290 years and speeds below 10^9.
[[nodiscard]] std::int64_t distance_in(Clock::duration elapsed, std::int64_t units_per_second) noexcept;

}  // namespace fieldbridge::sim
