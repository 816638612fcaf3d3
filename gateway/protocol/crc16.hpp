#pragma once
/// @file crc16.hpp
/// CRC-16/MODBUS (polynomial 0xA001 reflected, initial 0xFFFF), used by Modbus-RTU
/// (sent low byte first) and by the WTEC ASCII protocol (written as 4 hex digits,
/// high byte first). libmodbus keeps its CRC function private, hence this one.

#include <cstdint>

#include "protocol/bytes.hpp"

namespace fieldbridge::protocol {

[[nodiscard]] std::uint16_t crc16_modbus(ByteView data) noexcept;

}  // namespace fieldbridge::protocol
