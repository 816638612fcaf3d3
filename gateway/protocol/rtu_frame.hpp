#pragma once
/// @file rtu_frame.hpp
/// Modbus-RTU ADU framing: address + PDU + CRC-16 (low byte first, Modbus over
/// Serial Line V1.02, 2.5.1.2). Frames are delimited by the length predicted from
/// the function code; silence timers are only the resynchronisation backstop.

#include <cstdint>

#include "protocol/bytes.hpp"
#include "protocol/decode_result.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::protocol {

inline constexpr std::size_t max_rtu_adu_size = 256;
inline constexpr std::uint8_t modbus_broadcast_address = 0;
inline constexpr std::uint8_t excd_broadcast_address = 0xFF;

struct RtuFrame {
    std::uint8_t address = 0;
    Bytes pdu;
    bool operator==(const RtuFrame&) const = default;
};

/// address + pdu + CRC. Throws core::InvalidArgument for an empty PDU or one above
/// max_pdu_size.
[[nodiscard]] Bytes encode_rtu(std::uint8_t address, ByteView pdu);

/// Decodes one exact ADU (length known from outside): CRC checked, at least 4 bytes.
/// Never need_more; malformed (bad_length below 4 bytes, oversize above 256, bad_crc)
/// with `consumed` = the whole input.
[[nodiscard]] DecodeResult<RtuFrame> decode_rtu(ByteView adu);

/// Frames a reply in a receive buffer that may begin with garbage or local echo.
/// Expected: from @p address, answering @p request (a decoded request PDU).
/// - need_more: a plausible reply is still arriving;
/// - complete: `consumed` = bytes up to the end of the reply (including skipped garbage);
/// - malformed: drop `consumed` bytes and call again (error says why: bad_crc,
///   wrong_address, wrong_function...).
/// Opaque requests are framed by scanning for the shortest prefix whose CRC verifies.
///
/// Resynchronisation: every start offset is tried; the first complete CRC-valid reply
/// wins (a reply with a byte count other than the request implies is never one).
/// Bytes that cannot start the reply are reported malformed only when no reply could
/// follow them in this buffer; the error is the first dropped byte's (wrong_address,
/// wrong_function...), or bad_crc / unexpected_reply when a later dropped start matched
/// address and function but failed the CRC or the byte count.
///
/// Local echo is NOT detected: the caller discards exactly the number of bytes it
/// sent, as they come back, before framing (an FC05/FC06 echo equals the reply).
/// A broadcast (@p address 0 or 0xFF, the EXCD203MB broadcast) is never answered and
/// the caller does not wait: any bytes are malformed (unexpected_reply), never complete.
[[nodiscard]] DecodeResult<RtuFrame> frame_rtu_response(ByteView rx, std::uint8_t address,
                                                        const Request& request);

/// Frames a request (server / simulator side) by the length predicted from its
/// function code; for unknown function codes, by the shortest CRC-valid prefix of at
/// least 4 bytes (need_more until one verifies or 256 bytes are there). Resynchronises
/// like frame_rtu_response; a function code 0 or >= 0x80 cannot start a request
/// (bad_value). Counts and byte counts are not judged here: decode_request does that,
/// so the server can answer exception 03.
[[nodiscard]] DecodeResult<RtuFrame> frame_rtu_request(ByteView rx);

/// Characters on the wire for @p bytes at 8N1/8E1 etc: 11 bits a byte with parity
/// or 2 stop bits, 10 otherwise (Modbus over Serial Line, 2.5.1).
[[nodiscard]] constexpr unsigned bits_per_character(bool parity, unsigned stop_bits) noexcept {
    return 1 + 8 + (parity ? 1u : 0u) + stop_bits;
}

}  // namespace fieldbridge::protocol
