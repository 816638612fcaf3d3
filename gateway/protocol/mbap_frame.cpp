// Modbus TCP MBAP framing. Section numbers cite Modbus Messaging on TCP/IP
// Implementation Guide V1.0b.
#include "protocol/mbap_frame.hpp"

#include <stdexcept>
#include <string>

#include "core/error.hpp"

namespace fieldbridge::protocol {
namespace {

using MbapResult = DecodeResult<MbapFrame>;

// Byte offsets in the MBAP header (3.1.3).
constexpr std::size_t transaction_offset = 0;
constexpr std::size_t protocol_offset = 2;
constexpr std::size_t length_offset = 4;
constexpr std::size_t unit_offset = 6;

/// The length field counts the unit id and the PDU; the 6 bytes before it are not counted.
constexpr std::size_t bytes_before_length_payload = unit_offset;

}  // namespace

Bytes encode_mbap(std::uint16_t transaction_id, core::UnitId unit_id, ByteView pdu) {
    if (pdu.empty() || pdu.size() > mbap_max_length - 1U) {
        throw core::InvalidArgument("Modbus TCP frame (transaction " + std::to_string(transaction_id) +
                                    "): PDU of " + std::to_string(pdu.size()) +
                                    " bytes is outside 1.." + std::to_string(mbap_max_length - 1));
    }
    Bytes out;
    out.reserve(mbap_header_size + pdu.size());
    put_u16_be(out, transaction_id);
    put_u16_be(out, 0);  // protocol identifier: 0 = Modbus
    put_u16_be(out, static_cast<std::uint16_t>(pdu.size() + 1));
    out.push_back(unit_id.value);
    out.insert(out.end(), pdu.begin(), pdu.end());
    return out;
}

DecodeResult<MbapFrame> decode_mbap(ByteView stream) {
    const std::size_t size = stream.size();
    // Judge each header field as soon as its bytes are there: a client that sends a
    // wrong protocol id or length gets its connection closed without waiting for more.
    for (std::size_t i = protocol_offset; i < protocol_offset + 2 && i < size; ++i) {
        if (stream[i] != 0) return MbapResult::bad(DecodeError::bad_protocol_id, size);
    }
    // A non-zero high byte of the length already means a length of 256 or more.
    if (size > length_offset && stream[length_offset] != 0) {
        return MbapResult::bad(DecodeError::oversize, size);
    }
    if (size < length_offset + 2) return MbapResult::more();
    const std::uint16_t length = get_u16_be(stream, length_offset);
    if (length < mbap_min_length) return MbapResult::bad(DecodeError::bad_length, size);
    if (length > mbap_max_length) return MbapResult::bad(DecodeError::oversize, size);
    const std::size_t frame_size = bytes_before_length_payload + length;
    if (size < frame_size) return MbapResult::more();
    const ByteView pdu = stream.subspan(mbap_header_size, frame_size - mbap_header_size);
    return MbapResult::ok(MbapFrame{get_u16_be(stream, transaction_offset), core::UnitId{stream[unit_offset]},
                                    Bytes(pdu.begin(), pdu.end())},
                          frame_size);
}

}  // namespace fieldbridge::protocol
