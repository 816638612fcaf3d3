// Modbus-RTU framing: exact decoding, reply framing with resynchronisation, request
// framing, and a fuzz loop. Frames are from tests/vectors/vectors.yaml (seed 001 XEG).
#include <doctest/doctest.h>

#include <cstdint>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "protocol/crc16.hpp"
#include "protocol/rtu_frame.hpp"
#include "vectors.hpp"

namespace {

namespace p = fieldbridge::protocol;
using p::Bytes;
using p::ByteView;

template <typename T>
std::string describe_consumed(const p::DecodeResult<T>& r) {
    switch (r.status) {
        case p::DecodeStatus::need_more: return "need_more";
        case p::DecodeStatus::complete: return "complete " + std::to_string(r.consumed);
        case p::DecodeStatus::malformed:
            return "malformed " + std::string(p::to_string(r.error)) + " " + std::to_string(r.consumed);
    }
    return "?";
}

using fieldbridge::test::hex;

Bytes concat(std::initializer_list<ByteView> parts) {
    Bytes out;
    for (const auto part : parts) out.insert(out.end(), part.begin(), part.end());
    return out;
}

Bytes random_bytes(std::mt19937& rng, std::size_t n) {
    Bytes out(n);
    for (auto& b : out) b = static_cast<std::uint8_t>(rng());
    return out;
}

// XEG, id 2 (seed 001, Appendix 1 and section 5).
const p::Request read_model = p::ReadRegistersRequest{0x03, 0x0600, 1};
const Bytes read_model_request = {0x02, 0x03, 0x06, 0x00, 0x00, 0x01, 0x84, 0xB1};
const Bytes read_model_reply = {0x02, 0x03, 0x02, 0x0A, 0x20, 0xFB, 0x3C};
const p::Request write_model = p::WriteMultipleRegistersRequest{0x0600, {0x0A20}};
const Bytes write_model_request = {0x02, 0x10, 0x06, 0x00, 0x00, 0x01, 0x02, 0x0A, 0x20, 0xD3, 0xD8};
const Bytes write_model_reply = {0x02, 0x10, 0x06, 0x00, 0x00, 0x01, 0x01, 0x72};
const p::Request write_0611 = p::WriteSingleRegisterRequest{0x0611, 0x0001};
const Bytes write_0611_request = {0x02, 0x06, 0x06, 0x11, 0x00, 0x01, 0x18, 0xB4};
const Bytes exception_reply = {0x02, 0x86, 0x02, 0x33, 0xA1};

/// What a line worker does with a byte stream: frame after every chunk, drop what is
/// malformed, stop at the first reply. Returns the reply's frame bytes and the errors.
struct StreamOutcome {
    std::optional<p::RtuFrame> frame;
    std::size_t frame_end = 0;  ///< offset in the stream just after the reply
    std::vector<p::DecodeError> errors;
};

StreamOutcome feed_in_chunks(ByteView stream, std::size_t chunk, std::uint8_t address,
                             const p::Request& request) {
    StreamOutcome out;
    Bytes rx;
    std::size_t dropped = 0;
    for (std::size_t at = 0; at < stream.size() && !out.frame; at += chunk) {
        const ByteView part = stream.subspan(at, std::min(chunk, stream.size() - at));
        rx.insert(rx.end(), part.begin(), part.end());
        for (;;) {
            const auto r = p::frame_rtu_response(rx, address, request);
            if (r.need_more()) break;
            REQUIRE(r.consumed > 0);
            REQUIRE(r.consumed <= rx.size());
            if (r.complete()) {
                out.frame = r.value;
                out.frame_end = dropped + r.consumed;
                break;
            }
            out.errors.push_back(r.error);
            rx.erase(rx.begin(), rx.begin() + static_cast<std::ptrdiff_t>(r.consumed));
            dropped += r.consumed;
        }
    }
    return out;
}

}  // namespace

TEST_CASE("rtu: encode_rtu puts the CRC low byte first") {
    CHECK(p::encode_rtu(0x02, Bytes{0x03, 0x06, 0x00, 0x00, 0x01}) == read_model_request);
    CHECK(p::encode_rtu(0x02, Bytes{0x86, 0x02}) == exception_reply);
    CHECK(p::encode_rtu(0x02, Bytes{0x07}) == Bytes{0x02, 0x07, 0x41, 0x12});
    CHECK(p::encode_rtu(0xF7, Bytes(p::max_pdu_size, 0x41)).size() == p::max_rtu_adu_size);
    CHECK_THROWS_AS((void)p::encode_rtu(0x02, Bytes{}), fieldbridge::core::InvalidArgument);
    CHECK_THROWS_AS((void)p::encode_rtu(0x02, Bytes(p::max_pdu_size + 1, 0x41)), fieldbridge::core::InvalidArgument);
}

TEST_CASE("rtu: decode_rtu boundaries") {
    const auto ok = p::decode_rtu(read_model_reply);
    CHECK(describe_consumed(ok) == "complete 7");
    CHECK(ok.value == p::RtuFrame{0x02, {0x03, 0x02, 0x0A, 0x20}});
    CHECK(describe_consumed(p::decode_rtu(Bytes{0x02, 0x07, 0x41, 0x12})) == "complete 4");

    for (std::size_t len = 0; len < 4; ++len) {
        CAPTURE(len);
        CHECK(describe_consumed(p::decode_rtu(ByteView(read_model_reply).first(len))) ==
              "malformed bad_length " + std::to_string(len));
    }
    for (std::size_t len = 4; len < read_model_reply.size(); ++len) {
        CAPTURE(len);
        CHECK(describe_consumed(p::decode_rtu(ByteView(read_model_reply).first(len))) ==
              "malformed bad_crc " + std::to_string(len));
    }
    Bytes longest = p::encode_rtu(0x01, Bytes(p::max_pdu_size, 0x41));
    CHECK(describe_consumed(p::decode_rtu(longest)) == "complete 256");
    longest.insert(longest.begin() + 1, 0x41);
    CHECK(describe_consumed(p::decode_rtu(longest)) == "malformed oversize 257");

    for (std::size_t i = 0; i < read_model_reply.size(); ++i) {
        for (unsigned bit = 0; bit < 8; ++bit) {
            Bytes corrupted = read_model_reply;
            corrupted[i] = static_cast<std::uint8_t>(corrupted[i] ^ (1U << bit));
            CAPTURE(hex(corrupted));
            CHECK(describe_consumed(p::decode_rtu(corrupted)) == "malformed bad_crc 7");
        }
    }
}

TEST_CASE("rtu: a reply arriving byte by byte is need_more until complete") {
    struct Case {
        const char* name;
        p::Request request;
        Bytes reply;
    };
    const std::vector<Case> cases = {
        {"FC03", read_model, read_model_reply},
        {"FC10", write_model, write_model_reply},
        {"FC06 exception", write_0611, exception_reply},
        {"FC10 exception", write_model, p::encode_rtu(0x02, Bytes{0x90, 0x02})},
        {"FC07", p::ReadExceptionStatusRequest{}, {0x02, 0x07, 0x02, 0x53, 0xF1}},
        {"FC02", p::ReadBitsRequest{0x02, 0x0000, 8}, {0x02, 0x02, 0x01, 0x22, 0x21, 0xD5}},
    };
    for (const auto& c : cases) {
        CAPTURE(std::string(c.name));
        for (std::size_t len = 0; len < c.reply.size(); ++len) {
            CAPTURE(len);
            CHECK(describe_consumed(p::frame_rtu_response(ByteView(c.reply).first(len), 0x02, c.request)) == "need_more");
        }
        const auto r = p::frame_rtu_response(c.reply, 0x02, c.request);
        CHECK(describe_consumed(r) == "complete " + std::to_string(c.reply.size()));
        CHECK(p::encode_rtu(r.value.address, r.value.pdu) == c.reply);
        // Whatever follows the reply is left for later.
        CHECK(describe_consumed(p::frame_rtu_response(concat({c.reply, Bytes{0x02, 0x03}}), 0x02, c.request)) ==
              "complete " + std::to_string(c.reply.size()));
    }
}

TEST_CASE("rtu: the 5-byte exception reply to an FC16 write whose reply would be 8") {
    const Bytes exception = p::encode_rtu(0x02, Bytes{0x90, 0x04});
    REQUIRE(exception.size() == 5);
    const auto r = p::frame_rtu_response(exception, 0x02, write_model);
    CHECK(describe_consumed(r) == "complete 5");
    CHECK(r.value.pdu == Bytes{0x90, 0x04});
    CHECK(describe_consumed(p::frame_rtu_response(write_model_reply, 0x02, write_model)) == "complete 8");
}

TEST_CASE("rtu: garbage before a reply is skipped and counted in consumed") {
    std::mt19937 rng(4242U);
    const std::vector<std::pair<p::Request, Bytes>> replies = {
        {read_model, read_model_reply}, {write_model, write_model_reply}, {write_0611, exception_reply}};
    for (int round = 0; round < 2000; ++round) {
        const auto& [request, reply] = replies[static_cast<std::size_t>(round) % replies.size()];
        const Bytes garbage = random_bytes(rng, 1 + rng() % 40);
        const Bytes rx = concat({garbage, reply});
        const auto r = p::frame_rtu_response(rx, 0x02, request);
        if (!r.complete() || r.consumed != rx.size()) {
            FAIL_CHECK(describe_consumed(r) << " for " << hex(rx));
        } else if (p::encode_rtu(r.value.address, r.value.pdu) != reply) {
            FAIL_CHECK("wrong frame for " << hex(rx));
        }
    }
    // Typical line noise at bus turnaround: a few 0x00 / 0xFF bytes.
    const Bytes noisy = concat({Bytes{0x00, 0xFF, 0x00}, read_model_reply});
    CHECK(describe_consumed(p::frame_rtu_response(noisy, 0x02, read_model)) == "complete 10");
}

TEST_CASE("rtu: garbage then a reply, delivered in chunks as a line worker reads") {
    std::mt19937 rng(777U);
    for (int round = 0; round < 500; ++round) {
        const Bytes garbage = random_bytes(rng, rng() % 30);
        const Bytes stream = concat({garbage, write_model_reply});
        const std::size_t chunk = 1 + rng() % 6;
        const auto out = feed_in_chunks(stream, chunk, 0x02, write_model);
        if (!out.frame || out.frame_end != stream.size() ||
            p::encode_rtu(out.frame->address, out.frame->pdu) != write_model_reply) {
            FAIL_CHECK("reply not found in " << hex(stream) << " chunk " << chunk);
        }
    }
}

TEST_CASE("rtu: wrong address, wrong function, bad CRC, unexpected byte count") {
    // A well-formed reply from device 3 while device 2 was asked.
    const Bytes from_3 = p::encode_rtu(0x03, Bytes{0x03, 0x02, 0x0A, 0x20});
    CHECK(describe_consumed(p::frame_rtu_response(from_3, 0x02, read_model)) == "malformed wrong_address 7");
    // Device 2 answers another function.
    const Bytes fc04 = p::encode_rtu(0x02, Bytes{0x04, 0x02, 0x0A, 0x20});
    CHECK(describe_consumed(p::frame_rtu_response(fc04, 0x02, read_model)) == "malformed wrong_function 7");
    const Bytes exception_84 = p::encode_rtu(0x02, Bytes{0x84, 0x02});
    CHECK(describe_consumed(p::frame_rtu_response(exception_84, 0x02, read_model)) == "malformed wrong_function 5");
    // Two registers where one was asked: framed by its own byte count, a whole frame
    // with a good CRC from the device asked (decode_response refuses it:
    // unexpected_reply), so the line answers at once instead of waiting for a timeout.
    const Bytes two_regs = p::encode_rtu(0x02, Bytes{0x03, 0x04, 0x0A, 0x20, 0x00, 0x00});
    const auto framed_two = p::frame_rtu_response(two_regs, 0x02, read_model);
    REQUIRE(framed_two.complete());
    CHECK(framed_two.consumed == 9);
    CHECK(p::decode_response(framed_two.value.pdu, read_model).error == p::DecodeError::unexpected_reply);
    CHECK(p::frame_rtu_response(ByteView(two_regs).first(3), 0x02, read_model).need_more());
    // The same byte count with a CRC that fails over that length: not a frame.
    Bytes two_regs_bad = two_regs;
    two_regs_bad.back() ^= 0x01;
    const auto bad_crc = p::frame_rtu_response(two_regs_bad, 0x02, read_model);
    CHECK(bad_crc.malformed());
    CHECK(bad_crc.consumed == 9);
    // One register where three were asked: framed, refused by the decoder.
    const p::Request read3 = p::ReadRegistersRequest{0x03, 0x0A20, 3};
    const Bytes none = p::encode_rtu(0x02, Bytes{0x03, 0x02, 0x00, 0x07});
    const auto framed_short = p::frame_rtu_response(none, 0x02, read3);
    REQUIRE(framed_short.complete());
    CHECK(p::decode_response(framed_short.value.pdu, read3).error == p::DecodeError::unexpected_reply);
    // A request whose reply could not fit an ADU (200 registers).
    const p::Request too_many = p::ReadRegistersRequest{0x03, 0, 200};
    CHECK(describe_consumed(p::frame_rtu_response(Bytes{0x02, 0x03, 0x90}, 0x02, too_many)) == "malformed oversize 3");

    // Every byte of the reply corrupted, one bit at a time: never a reply.
    for (std::size_t i = 0; i < read_model_reply.size(); ++i) {
        for (unsigned bit = 0; bit < 8; ++bit) {
            Bytes corrupted = read_model_reply;
            corrupted[i] = static_cast<std::uint8_t>(corrupted[i] ^ (1U << bit));
            CAPTURE(hex(corrupted));
            const auto r = p::frame_rtu_response(corrupted, 0x02, read_model);
            CHECK_FALSE(r.complete());
            if (i == 0) CHECK(r.error == p::DecodeError::wrong_address);
            // 0x83 is the exception of FC03: then a 5-byte exception with a bad CRC.
            if (i == 1) CHECK(r.error == (bit == 7 ? p::DecodeError::bad_crc : p::DecodeError::wrong_function));
            if (i >= 3) CHECK(describe_consumed(r) == "malformed bad_crc 7");
        }
    }
    // Noise, then a corrupted reply: the more telling reason (bad CRC) is reported.
    Bytes corrupted = read_model_reply;
    corrupted[4] = 0x21;
    CHECK(describe_consumed(p::frame_rtu_response(concat({Bytes{0x55, 0x00}, corrupted}), 0x02, read_model)) ==
          "malformed bad_crc 9");
}

TEST_CASE("rtu: bytes before a partial reply are dropped, then the reply completes") {
    const Bytes rx = concat({Bytes{0x55, 0xAA, 0x13}, ByteView(read_model_reply).first(4)});
    const auto first = p::frame_rtu_response(rx, 0x02, read_model);
    CHECK(describe_consumed(first) == "malformed wrong_address 3");
    CHECK(describe_consumed(p::frame_rtu_response(ByteView(rx).subspan(3), 0x02, read_model)) == "need_more");
}

TEST_CASE("rtu: local echo is the caller's job; reads and multiple writes survive it anyway") {
    // Echo of an FC03 request carries byte "count" 0x06: it cannot be the reply.
    const auto read = p::frame_rtu_response(concat({read_model_request, read_model_reply}), 0x02, read_model);
    CHECK(describe_consumed(read) == "complete 15");
    CHECK(read.value.pdu == Bytes{0x03, 0x02, 0x0A, 0x20});
    // Echo of an FC10 request: its first 8 bytes fail the CRC of an 8-byte reply.
    const auto write = p::frame_rtu_response(concat({write_model_request, write_model_reply}), 0x02, write_model);
    CHECK(describe_consumed(write) == "complete 19");
    CHECK(write.value.pdu == Bytes{0x10, 0x06, 0x00, 0x00, 0x01});
    // FC06: echo and reply are the same bytes (seed 003 shows FC06 replies equal to the
    // requests), so the echo would be taken for the reply. This is why the line worker
    // discards exactly the bytes it sent before framing.
    const Bytes init_request = {0x01, 0x06, 0x01, 0x00, 0x00, 0x01, 0x49, 0xF6};
    const p::Request init = p::WriteSingleRegisterRequest{0x0100, 1};
    const auto echo = p::frame_rtu_response(concat({init_request, exception_reply}), 0x01, init);
    CHECK(describe_consumed(echo) == "complete 8");
    CHECK(echo.value.pdu == Bytes(init_request.begin() + 1, init_request.end() - 2));
}

TEST_CASE("rtu: broadcasts are never answered") {
    const Bytes anything = {0x00, 0x10, 0x06, 0x30, 0x00, 0x03, 0x41, 0x47};
    for (const std::uint8_t broadcast : {p::modbus_broadcast_address, p::excd_broadcast_address}) {
        CAPTURE(static_cast<int>(broadcast));
        CHECK(describe_consumed(p::frame_rtu_response({}, broadcast, write_model)) == "need_more");
        CHECK(describe_consumed(p::frame_rtu_response(anything, broadcast, write_model)) == "malformed unexpected_reply 8");
        const Bytes would_be_reply = p::encode_rtu(broadcast, Bytes{0x10, 0x06, 0x00, 0x00, 0x01});
        CHECK(describe_consumed(p::frame_rtu_response(would_be_reply, broadcast, write_model)) ==
              "malformed unexpected_reply 8");
    }
}

TEST_CASE("rtu: replies to opaque requests are framed by the shortest CRC-valid prefix") {
    const p::Request report_id = p::OpaqueRequest{0x11, {}};
    const Bytes reply = p::encode_rtu(0x02, Bytes{0x11, 0x03, 0x42, 0xFF, 0x07});
    for (std::size_t len = 0; len < reply.size(); ++len) {
        CAPTURE(len);
        CHECK(describe_consumed(p::frame_rtu_response(ByteView(reply).first(len), 0x02, report_id)) == "need_more");
    }
    const auto r = p::frame_rtu_response(concat({reply, Bytes{0x02, 0x11}}), 0x02, report_id);
    CHECK(describe_consumed(r) == "complete 8");
    CHECK(r.value.pdu == Bytes{0x11, 0x03, 0x42, 0xFF, 0x07});
    const Bytes exception = p::encode_rtu(0x02, Bytes{0x91, 0x01});
    CHECK(describe_consumed(p::frame_rtu_response(exception, 0x02, report_id)) == "complete 5");
    // 256 bytes and still no CRC match: not a reply.
    Bytes endless = {0x02, 0x11};
    std::mt19937 rng(11U);
    while (endless.size() < p::max_rtu_adu_size) {
        endless.push_back(static_cast<std::uint8_t>(rng()));
        if (p::crc16_modbus(endless) == 0) endless.back() = static_cast<std::uint8_t>(endless.back() ^ 1U);
    }
    const auto never = p::frame_rtu_response(endless, 0x02, report_id);
    CHECK_FALSE(never.complete());
    if (never.malformed()) CHECK(never.error == p::DecodeError::bad_crc);
}

TEST_CASE("rtu: frame_rtu_request") {
    const std::vector<Bytes> requests = {
        read_model_request,
        write_model_request,
        write_0611_request,
        {0x02, 0x07, 0x41, 0x12},
        {0x02, 0x02, 0x00, 0x00, 0x00, 0x08, 0x79, 0xFF},
        p::encode_rtu(0x01, Bytes{0x0F, 0x00, 0x13, 0x00, 0x0A, 0x02, 0xCD, 0x01}),
        p::encode_rtu(0x01, Bytes{0x17, 0x00, 0x03, 0x00, 0x06, 0x00, 0x0E, 0x00, 0x01, 0x02, 0x00, 0xFF}),
        p::encode_rtu(0x01, Bytes{0x41, 0x10, 0x20}),  // opaque: shortest CRC-valid prefix
        p::encode_rtu(0x01, Bytes{0x11}),
    };
    for (const auto& request : requests) {
        CAPTURE(hex(request));
        for (std::size_t len = 0; len < request.size(); ++len) {
            CAPTURE(len);
            CHECK(describe_consumed(p::frame_rtu_request(ByteView(request).first(len))) == "need_more");
        }
        const auto r = p::frame_rtu_request(request);
        CHECK(describe_consumed(r) == "complete " + std::to_string(request.size()));
        CHECK(p::encode_rtu(r.value.address, r.value.pdu) == request);
    }
    // Pipelined: the first request only, then the second from where it ended.
    const Bytes two = concat({read_model_request, write_model_request});
    const auto first = p::frame_rtu_request(two);
    CHECK(describe_consumed(first) == "complete 8");
    CHECK(describe_consumed(p::frame_rtu_request(ByteView(two).subspan(first.consumed))) == "complete 11");
    // Garbage before a request.
    CHECK(describe_consumed(p::frame_rtu_request(concat({Bytes{0xFF, 0x00}, read_model_request}))) == "complete 10");
    // Function code 0 or with the exception flag cannot start a request.
    // (the last byte may still be the address of a request that follows).
    CHECK(describe_consumed(p::frame_rtu_request(Bytes{0x02, 0x83})) == "malformed bad_value 1");
    CHECK(describe_consumed(p::frame_rtu_request(Bytes{0x02, 0x00, 0x83, 0x80})) == "malformed bad_value 3");
    // Address 0 followed by a valid function code is a broadcast request arriving.
    CHECK(describe_consumed(p::frame_rtu_request(Bytes{0x02, 0x00, 0x05, 0x80})) == "malformed bad_value 1");
    // A byte count that makes the ADU longer than 256 bytes.
    const auto oversize = p::frame_rtu_request(Bytes{0x02, 0x10, 0x00, 0x00, 0x00, 0x7F, 0xFE});
    CHECK(oversize.malformed());
    CHECK(oversize.error == p::DecodeError::oversize);
    // A corrupted CRC is reported and dropped.
    Bytes corrupted = read_model_request;
    corrupted.back() = static_cast<std::uint8_t>(corrupted.back() ^ 0x01);
    const auto bad = p::frame_rtu_request(corrupted);
    CHECK(bad.malformed());
    CHECK(bad.error == p::DecodeError::bad_crc);
    CHECK(bad.consumed >= 1);
}

TEST_CASE("rtu: fuzz - framers never crash and always make progress") {
    std::mt19937 rng(20240602U);
    const std::vector<p::Request> requests = {
        read_model,
        write_model,
        write_0611,
        p::ReadBitsRequest{0x01, 0, 19},
        p::WriteSingleCoilRequest{0x00AC, true},
        p::ReadExceptionStatusRequest{},
        p::ReadWriteRegistersRequest{0x0003, 6, 0x000E, {0x00FF}},
        p::OpaqueRequest{0x11, {}},
    };
    const std::vector<Bytes> seeds = {read_model_reply, write_model_reply, exception_reply, read_model_request,
                                      write_model_request};
    int completes = 0;
    for (int round = 0; round < 20000; ++round) {
        Bytes rx;
        if (round % 2 == 0) {
            rx = concat({random_bytes(rng, rng() % 8), seeds[rng() % seeds.size()], random_bytes(rng, rng() % 8)});
            if (!rx.empty() && rng() % 2 == 0) rx[rng() % rx.size()] = static_cast<std::uint8_t>(rng());
        } else {
            rx = random_bytes(rng, round % 50 == 1 ? rng() % 600 : rng() % 64);
            if (rx.size() > 1 && rng() % 2 == 0) rx[0] = 0x02;
        }
        const auto& request = requests[rng() % requests.size()];
        const std::uint8_t address = (rng() % 4 == 0) ? static_cast<std::uint8_t>(rng()) : 0x02;

        const auto exact = p::decode_rtu(rx);
        if (exact.consumed > rx.size()) FAIL_CHECK("decode_rtu consumed too much: " << hex(rx));
        for (const auto& r : {p::frame_rtu_response(rx, address, request), p::frame_rtu_request(rx)}) {
            if (r.consumed > rx.size()) FAIL_CHECK("consumed beyond the buffer: " << hex(rx));
            if (r.malformed() && r.consumed == 0) FAIL_CHECK("malformed without progress: " << hex(rx));
            if (r.need_more() && r.consumed != 0) FAIL_CHECK("need_more consumed bytes: " << hex(rx));
            if (r.complete()) {
                ++completes;
                // The frame is the CRC-valid tail of what was consumed.
                const Bytes adu = p::encode_rtu(r.value.address, r.value.pdu);
                const ByteView tail = ByteView(rx).subspan(r.consumed - adu.size(), adu.size());
                if (Bytes(tail.begin(), tail.end()) != adu) FAIL_CHECK("frame is not what was consumed: " << hex(rx));
            }
        }
    }
    CHECK(completes > 2000);  // the seeded rounds do reach the success paths
}
