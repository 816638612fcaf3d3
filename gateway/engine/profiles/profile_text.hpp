#pragma once
/// @file profile_text.hpp
/// Small text helpers for decoded state, alarms and notices.

#include <cstdint>
#include <string>

namespace fieldbridge::engine {

/// "0x02".
[[nodiscard]] std::string hex_byte(std::uint8_t value);
/// "0x0A20".
[[nodiscard]] std::string hex_word(std::uint16_t value);

}  // namespace fieldbridge::engine
