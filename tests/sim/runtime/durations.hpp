#pragma once
/// @file durations.hpp
/// Durations as operators type them on the command line and the control socket:
/// "1ms", "250us", "1.5s", "2m"; a bare number takes the option's documented unit.

#include <chrono>
#include <string>
#include <string_view>

namespace fieldbridge::sim::runtime {

using Clock = std::chrono::steady_clock;

enum class DefaultUnit : unsigned char { microseconds, milliseconds, seconds };

/// Parses a non-negative duration. Throws SimError naming @p what on bad input.
[[nodiscard]] Clock::duration parse_duration(std::string_view text, DefaultUnit unit,
                                             std::string_view what);

/// "1.250 ms" style text for logs.
[[nodiscard]] std::string format_duration(Clock::duration duration);

/// Microseconds as a double, for statistics.
[[nodiscard]] double to_us(Clock::duration duration) noexcept;

}  // namespace fieldbridge::sim::runtime
