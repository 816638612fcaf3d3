#pragma once
/// @file line_limit.hpp
/// The physical limit of a benchmark's line (spec section 9): T_line of the shape's
/// read and write at the line's baud (8N1, 10 bits per character, t3.5 = 3.5
/// characters as the daemon keeps it: engine::InterFrameRule::per_character) and
/// the simulator's device turnaround.
#include <chrono>
#include <cstdint>

#include "load_shape.hpp"

namespace fieldbridge::bench {

struct LineLimit {
    std::uint32_t baud = 115200;
    double t_read_ms = 0.0;   ///< T_line of one read: request, reply, 2 x t3.5, turnaround
    double t_write_ms = 0.0;  ///< the same for the shape's write
    double t3_5_us = 0.0;
    double limit_tps = 0.0;   ///< 1 / T_line of the read
    /// Priority ideal of a write under saturating reads: its own T_line plus half
    /// (p50) or all (max) of the read in flight.
    [[nodiscard]] double write_ideal_p50_ms() const noexcept { return t_write_ms + t_read_ms / 2.0; }
    [[nodiscard]] double write_ideal_max_ms() const noexcept { return t_write_ms + t_read_ms; }
};

[[nodiscard]] LineLimit line_limit(const LoadShape& shape, std::uint32_t baud, std::chrono::nanoseconds turnaround);

}  // namespace fieldbridge::bench
