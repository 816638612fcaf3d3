#pragma once
/// @file mbap_frame.hpp
/// Modbus TCP MBAP framing (Modbus Messaging on TCP/IP V1.0b, 3.1.3):
/// transaction id, protocol id 0, length (unit id + PDU), unit id, PDU.
///
/// The unit identifier is a core::UnitId in the frame and the encoder's arguments
/// (protocol sits above core, docs/architecture.md "Layers"): the byte becomes one
/// where the header is read and goes back to a byte where it is written. The PDU
/// stays bytes; its function byte is the PDU codec's business (modbus_pdu.hpp).

#include <cstdint>

#include "core/modbus_ids.hpp"
#include "protocol/bytes.hpp"
#include "protocol/decode_result.hpp"

namespace fieldbridge::protocol {

inline constexpr std::size_t mbap_header_size = 7;
/// Length field covers unit id + PDU: at least 2 (unit + function), at most 254.
inline constexpr std::uint16_t mbap_min_length = 2;
inline constexpr std::uint16_t mbap_max_length = 254;

struct MbapFrame {
    std::uint16_t transaction_id = 0;
    core::UnitId unit_id;
    Bytes pdu;
    bool operator==(const MbapFrame&) const = default;
};

/// Throws core::InvalidArgument for an empty PDU or one longer than 253 bytes.
[[nodiscard]] Bytes encode_mbap(std::uint16_t transaction_id, core::UnitId unit_id, ByteView pdu);

/// Frames the first MBAP frame in a TCP byte stream. need_more until the header
/// and the announced length are there; malformed (bad_protocol_id, bad_length,
/// oversize) as soon as the header shows it, since the stream cannot resynchronise
/// (the server closes that connection). On malformed, `consumed` is the whole input.
/// Complete: `consumed` = 6 + length; bytes after it belong to the next frame.
[[nodiscard]] DecodeResult<MbapFrame> decode_mbap(ByteView stream);

}  // namespace fieldbridge::protocol
