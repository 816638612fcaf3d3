#pragma once
// Private helpers shared by modbus_pdu.cpp and modbus_pdu_response.cpp: field
// sizes, bit packing and argument checks. Not part of the public protocol API.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "protocol/bytes.hpp"

namespace fieldbridge::protocol::detail {

// FC05 wire values (Modbus Application Protocol V1.1b3, 6.5): anything else is illegal.
inline constexpr std::uint16_t coil_on = 0xFF00;
inline constexpr std::uint16_t coil_off = 0x0000;

// PDU sizes, function code included (Modbus Application Protocol V1.1b3, 6.1-6.17).
inline constexpr std::size_t address_value_pdu_size = 5;      // FC01-06 requests, FC05/06/0F/10 replies
inline constexpr std::size_t read_exception_status_request_size = 1;  // FC07: function code only
inline constexpr std::size_t write_multiple_header_size = 6;  // FC0F/10: fc, address, count, byte count
inline constexpr std::size_t mask_write_pdu_size = 7;         // FC16 request and reply: fc, address, and, or
inline constexpr std::size_t read_write_header_size = 10;     // FC17: fc, 2 x (address, count), byte count
inline constexpr std::size_t byte_count_reply_header_size = 2;  // fc + byte count
inline constexpr std::size_t two_byte_pdu_size = 2;           // exception reply, FC07 reply

template <class... Ts>
struct Overloaded : Ts... {
    using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

/// Bytes needed for @p bits coils or inputs.
[[nodiscard]] constexpr std::size_t bit_byte_count(std::size_t bits) noexcept { return (bits + 7) / 8; }

/// "FC03" style name for messages.
[[nodiscard]] std::string function_name(std::uint8_t function);

/// Throws core::InvalidArgument "Modbus FCxx <kind>: <what>".
[[noreturn]] void reject(std::uint8_t function, const char* kind, const std::string& what);

/// Throws unless 1 <= value <= max.
void check_quantity(std::uint8_t function, const char* kind, const char* field, std::size_t value,
                    std::size_t max);

/// Packs bits LSB first, the last byte padded with zeros (Modbus Application Protocol 6.1, 6.11).
void put_bits(Bytes& out, const std::vector<bool>& bits);

/// Unpacks the first @p count bits of @p bytes (the caller checks the bounds).
[[nodiscard]] std::vector<bool> get_bits(ByteView bytes, std::size_t count);

void put_registers(Bytes& out, const std::vector<std::uint16_t>& values);

/// @p bytes holds an even number of bytes, high byte first in each register.
[[nodiscard]] std::vector<std::uint16_t> get_registers(ByteView bytes);

}  // namespace fieldbridge::protocol::detail
