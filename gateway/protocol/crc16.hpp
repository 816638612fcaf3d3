#pragma once
/// @file crc16.hpp
/// CRC-16/MODBUS (polynomial 0xA001 reflected, initial 0xFFFF), used by Modbus-RTU
/// (sent low byte first) and by the WTEC ASCII protocol (written as 4 hex digits,
/// high byte first). libmodbus keeps its CRC function private, hence this one.

#include <cstdint>

#include "protocol/bytes.hpp"

namespace fieldbridge::protocol {

/// Initial register value of CRC-16/MODBUS.
inline constexpr std::uint16_t crc16_modbus_init = 0xFFFF;

/// CRC-16/MODBUS of @p data (check value: "123456789" -> 0x4B37).
[[nodiscard]] std::uint16_t crc16_modbus(ByteView data) noexcept;

/// Continues a CRC over more bytes: crc16_modbus_update(crc16_modbus(a), b) equals
/// the CRC of a followed by b. Over a whole RTU ADU, CRC bytes included (low byte
/// first), the result is 0: framers use this to test every prefix in one pass.
[[nodiscard]] std::uint16_t crc16_modbus_update(std::uint16_t crc, ByteView data) noexcept;

}  // namespace fieldbridge::protocol
