#pragma once
/// @file modbus_ids.hpp
/// Strong types for the three bytes that a Modbus request carries and that are easy to
/// swap when they all travel as `std::uint8_t`: the Modbus TCP unit identifier a client
/// addresses (MBAP header), the address of a device on its serial bus, and the function
/// byte of a PDU. A unit ID is not a bus address: the configuration maps one to the
/// other (`unit_id` and `address` of a device, docs/configuration.md).

#include <compare>
#include <cstdint>

namespace fieldbridge::core {

/// One byte with a meaning: explicit from a byte, `value` to go back to the wire.
template <class Tag>
struct ByteId {
    std::uint8_t value = 0;

    constexpr ByteId() noexcept = default;
    constexpr explicit ByteId(std::uint8_t byte) noexcept : value(byte) {}
    friend constexpr auto operator<=>(ByteId, ByteId) noexcept = default;
};

struct UnitIdTag {};
struct BusAddressTag {};
struct FunctionCodeTag {};

/// The unit identifier of a Modbus TCP request (MBAP byte 6), which the gateway
/// routes to a serial device, a line's broadcast unit or an upstream unit.
using UnitId = ByteId<UnitIdTag>;
/// A device's address on its RS-485 line (0 / 0xFF: the type's broadcast address).
using BusAddress = ByteId<BusAddressTag>;
/// The function byte of a PDU as it came: 1..127 are function codes, 0 and 0x80..0xFF
/// are not (is_function_code()), and are still answered with that byte | 0x80.
using FunctionCode = ByteId<FunctionCodeTag>;

/// True for the function codes Modbus defines room for: 1..127.
[[nodiscard]] constexpr bool is_function_code(FunctionCode function) noexcept {
    return function.value != 0 && function.value < 0x80;
}

}  // namespace fieldbridge::core
