#pragma once
/// @file modbus_request.hpp
/// What every simulated Modbus slave does around its register map: accept an RTU
/// frame addressed to it, decode the PDU, turn undecodable PDUs into exception 03,
/// and frame the reply (none for a broadcast).

#include <cstdint>
#include <optional>
#include <variant>

#include "protocol/bytes.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::sim {

/// A request PDU received in an RTU frame for this device.
struct AddressedPdu {
    protocol::Bytes pdu;
    bool broadcast = false;
};

/// The PDU of @p frame when its CRC verifies and it is addressed to @p address or to
/// @p broadcast (the bus's broadcast address; nullopt when the device has none).
[[nodiscard]] std::optional<AddressedPdu> accept_rtu(protocol::ByteView frame, std::uint8_t address,
                                                     std::optional<std::uint8_t> broadcast);

/// The reply ADU from @p address, or nullopt for a broadcast request (Modbus over
/// Serial Line V1.02, 2.1: broadcast requests are never answered).
[[nodiscard]] std::optional<protocol::Bytes> rtu_reply(const AddressedPdu& request,
                                                       std::uint8_t address,
                                                       const protocol::Response& response);

[[nodiscard]] protocol::Response exception_of(std::uint8_t function, protocol::ExceptionCode code);

/// The decoded request, or the exception a slave answers when the PDU breaks the
/// protocol (quantity 0 or above the limit, byte count not 2 x quantity, wrong
/// length): 03, as seed 001 section 5 lists for these cases.
[[nodiscard]] std::variant<protocol::Request, protocol::Response> decode_or_exception(
    protocol::ByteView pdu);

/// Splits a 32-bit value into two registers in the given word order.
struct WordPair {
    std::uint16_t first = 0;
    std::uint16_t second = 0;
};
[[nodiscard]] WordPair split_u32(std::uint32_t value, bool high_word_first) noexcept;
[[nodiscard]] std::uint32_t join_u32(std::uint16_t first, std::uint16_t second,
                                     bool high_word_first) noexcept;

}  // namespace fieldbridge::sim
