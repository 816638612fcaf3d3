#pragma once
/// @file bytes.hpp
/// Byte buffers and explicit big-endian field access (Modbus puts the high byte
/// first in every 16-bit field; only the RTU CRC goes low byte first).

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace fieldbridge::protocol {

using Bytes = std::vector<std::uint8_t>;
using ByteView = std::span<const std::uint8_t>;

/// Reads a big-endian 16-bit value at @p offset. The caller checks the bounds.
[[nodiscard]] constexpr std::uint16_t get_u16_be(ByteView bytes, std::size_t offset) noexcept {
    return static_cast<std::uint16_t>((bytes[offset] << 8) | bytes[offset + 1]);
}

/// Appends a 16-bit value high byte first.
inline void put_u16_be(Bytes& out, std::uint16_t value) {
    out.push_back(static_cast<std::uint8_t>(value >> 8));
    out.push_back(static_cast<std::uint8_t>(value & 0xFF));
}

}  // namespace fieldbridge::protocol
