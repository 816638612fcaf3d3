#pragma once
/// @file control_words.hpp
/// Parsing of the test/demo control commands every model accepts through
/// BusDevice::control(), e.g. "alarm 7", "object 20.5", "inputs 0x22".

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace fieldbridge::sim {

/// Splits on spaces and tabs; empty words are dropped.
[[nodiscard]] std::vector<std::string_view> split_words(std::string_view text);

/// A decimal integer with an optional sign, or hexadecimal with a 0x prefix.
[[nodiscard]] std::optional<std::int64_t> parse_integer(std::string_view text);

/// A decimal number with at most @p decimals fractional digits, returned scaled by
/// 10^decimals ("20.5" with 2 decimals -> 2050). No floating point involved.
[[nodiscard]] std::optional<std::int64_t> parse_fixed(std::string_view text, unsigned decimals);

/// The error text for a control command a model does not know, listing what it knows.
[[nodiscard]] std::string unknown_control(std::string_view device_type, std::string_view command,
                                          std::string_view known);

}  // namespace fieldbridge::sim
