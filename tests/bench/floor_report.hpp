#pragma once
/// @file floor_report.hpp
/// Prints a floor run (raw_master.hpp) the same way in every line benchmark: its
/// rate against the physical limit, its CPU per transaction, and the simulator
/// physics check (reply times and the master's silence, from the master's side).
#include "line_limit.hpp"
#include "raw_master.hpp"

namespace fieldbridge::bench {

/// Transactions per second of @p floor (0 when it ran no time).
[[nodiscard]] double floor_rate(const RawMasterResult& floor) noexcept;
/// User + kernel CPU per transaction of @p floor, in microseconds.
[[nodiscard]] double floor_cpu_us(const RawMasterResult& floor) noexcept;

/// "<bench> floor: ..." and "<bench> physics: ..." lines on stdout.
void print_floor(const char* bench, const RawMasterResult& floor, const LineLimit& limit);

}  // namespace fieldbridge::bench
