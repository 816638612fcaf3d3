// The Modbus-RTU reply framer (protocol/rtu_frame.hpp, frame_rtu_response) and the
// response PDU decoder after it, as the line master uses them (engine/line_codec.cpp):
// the reply arrives in chunks after the request went out; after each chunk the
// receive buffer is scanned; malformed bytes are dropped and the rest scanned again.
// Input: one byte choosing the chunk boundaries, one byte L, the request PDU
// (L bytes: the request the gateway sent), the slave address, then the received bytes.

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "protocol/modbus_pdu.hpp"
#include "protocol/rtu_frame.hpp"

namespace {

namespace protocol = fieldbridge::protocol;

/// Address + CRC around the PDU (Modbus over Serial Line V1.02, 2.5.1.1).
constexpr std::size_t rtu_overhead = 3;

/// Scans @p buffer until the framer needs more bytes, dropping what it rejects.
void drain(protocol::Bytes& buffer, std::uint8_t address, const protocol::Request& request) {
    const bool broadcast =
        address == protocol::modbus_broadcast_address || address == protocol::excd_broadcast_address;
    while (!buffer.empty()) {
        const auto framed = protocol::frame_rtu_response(buffer, address, request);
        if (framed.need_more()) return;
        // Anything but need_more takes bytes off the buffer: consumed 0 would make the
        // line master scan the same bytes forever.
        FB_FUZZ_CHECK(framed.consumed > 0 && framed.consumed <= buffer.size());
        if (framed.malformed()) {
            FB_FUZZ_CHECK(framed.error != protocol::DecodeError::none);
        } else {
            FB_FUZZ_CHECK(!broadcast);  // a broadcast is never answered
            const auto& frame = framed.value;
            FB_FUZZ_CHECK(frame.address == address);
            FB_FUZZ_CHECK(!frame.pdu.empty() && frame.pdu.size() <= protocol::max_pdu_size);
            FB_FUZZ_CHECK(frame.pdu.size() + rtu_overhead <= framed.consumed);
            // The frame is the last bytes consumed and re-encodes to them.
            const auto again = protocol::encode_rtu(frame.address, frame.pdu);
            FB_FUZZ_CHECK(std::equal(again.begin(), again.end(),
                             buffer.begin() + static_cast<std::ptrdiff_t>(framed.consumed - again.size())));
            const auto decoded = protocol::decode_response(frame.pdu, request);
            if (decoded.complete()) {
                // Response PDUs are bijective: the decoded reply re-encodes to its bytes.
                FB_FUZZ_CHECK(protocol::encode_response(decoded.value) == frame.pdu);
            } else {
                FB_FUZZ_CHECK(decoded.malformed() && decoded.consumed == frame.pdu.size());
            }
        }
        buffer.erase(buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(framed.consumed));
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    fieldbridge::fuzz::FuzzInput input(data, size);
    const std::uint8_t split = input.byte();
    const auto request_pdu = input.take(input.byte());
    const std::uint8_t address = input.byte();
    const auto rx = input.rest();

    // The gateway only sends requests it could encode: anything else is not a context
    // the framer can meet.
    const auto request = protocol::decode_request(request_pdu);
    if (!request.complete()) return 0;

    protocol::Bytes buffer;
    for (const auto chunk : fieldbridge::fuzz::chunks(rx, split)) {
        buffer.insert(buffer.end(), chunk.begin(), chunk.end());
        drain(buffer, address, request.value);
    }
    return 0;
}
