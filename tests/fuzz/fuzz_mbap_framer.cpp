// The MBAP stream framer (protocol/mbap_frame.hpp, decode_mbap) as the Modbus TCP
// server's connection and the R6 upstream link use it: bytes arrive in chunks, the
// framer is asked after each one, complete frames are taken off the front, and a
// malformed header ends the stream (the connection is closed).
// Input: one byte choosing the chunk boundaries, then the TCP byte stream.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fuzz_input.hpp"
#include "protocol/mbap_frame.hpp"

namespace {

namespace protocol = fieldbridge::protocol;

struct Framed {
    std::vector<protocol::MbapFrame> frames;
    bool closed = false;  ///< a malformed header was seen
};

/// Takes every complete frame off the front of @p buffer, as Connection::process does.
void drain(protocol::Bytes& buffer, Framed& out) {
    while (!out.closed && !buffer.empty()) {
        const auto result = protocol::decode_mbap(buffer);
        if (result.need_more()) {
            FB_FUZZ_CHECK(result.consumed == 0);
            return;
        }
        FB_FUZZ_CHECK(result.consumed <= buffer.size());
        if (result.malformed()) {
            FB_FUZZ_CHECK(result.consumed == buffer.size());
            FB_FUZZ_CHECK(result.error != protocol::DecodeError::none);
            out.closed = true;
            return;
        }
        const auto& frame = result.value;
        // Complete: the frame is header + PDU, within the protocol's bounds, and
        // re-encodes to exactly the bytes it was read from (MBAP framing is bijective).
        FB_FUZZ_CHECK(!frame.pdu.empty() && frame.pdu.size() <= protocol::mbap_max_length - 1u);
        FB_FUZZ_CHECK(result.consumed == protocol::mbap_header_size + frame.pdu.size());
        const auto again = protocol::encode_mbap(frame.transaction_id, frame.unit_id, frame.pdu);
        FB_FUZZ_CHECK(again.size() == result.consumed);
        FB_FUZZ_CHECK(std::equal(again.begin(), again.end(), buffer.begin()));
        out.frames.push_back(frame);
        buffer.erase(buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(result.consumed));
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    fieldbridge::fuzz::FuzzInput input(data, size);
    const std::uint8_t split = input.byte();
    const auto stream = input.rest();

    Framed chunked;
    protocol::Bytes buffer;
    for (const auto chunk : fieldbridge::fuzz::chunks(stream, split)) {
        if (chunked.closed) break;
        buffer.insert(buffer.end(), chunk.begin(), chunk.end());
        drain(buffer, chunked);
    }

    // However the stream was cut, the frames are those of the stream read at once.
    Framed whole;
    protocol::Bytes all(stream.begin(), stream.end());
    drain(all, whole);
    FB_FUZZ_CHECK(chunked.frames == whole.frames);
    FB_FUZZ_CHECK(chunked.closed == whole.closed);
    return 0;
}
