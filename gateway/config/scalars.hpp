#pragma once
/// @file scalars.hpp
/// Conversions of configuration scalars from their text, shared by the loader and by
/// the command-line tools. Each returns the value or a message saying what is wrong
/// and what was expected.

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>

#include "config/parsed.hpp"

namespace fieldbridge::config {

/// Decimal (`-12`, `502`) or hexadecimal with a 0x prefix (`0x0600`). Nothing else:
/// no octal, no underscores, no floats.
[[nodiscard]] Parsed<std::int64_t> parse_integer(std::string_view text);

/// A duration with its unit: `250ms`, `2s`, `1.5s`, `1min`. A bare number is an
/// error (the unit is never guessed); fractions must come to whole milliseconds.
[[nodiscard]] Parsed<std::chrono::milliseconds> parse_duration(std::string_view text);

/// Exactly `true` or `false` (not yes/no/on/off/1/0).
[[nodiscard]] Parsed<bool> parse_bool(std::string_view text);

/// A finite decimal number (`0.05`, `2`, `1e-3`).
[[nodiscard]] Parsed<double> parse_number(std::string_view text);

/// The shortest exact spelling in the config syntax: `1min`, `2s`, `250ms`.
[[nodiscard]] std::string format_duration(std::chrono::milliseconds d);

}  // namespace fieldbridge::config
