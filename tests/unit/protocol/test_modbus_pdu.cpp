// Modbus PDU codec. Examples marked "6.x" are the request / response examples of the
// Modbus Application Protocol Specification V1.1b3, section 6.x.
#include <doctest/doctest.h>

#include <cstdint>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "protocol/modbus_pdu.hpp"
#include "vectors.hpp"

namespace {

namespace p = fieldbridge::protocol;
using p::Bytes;
using p::ByteView;
using p::DecodeError;
using p::DecodeStatus;

using fieldbridge::test::hex;

std::vector<bool> bits_of(std::initializer_list<int> ones_and_zeros) {
    std::vector<bool> bits;
    for (const int b : ones_and_zeros) bits.push_back(b != 0);
    return bits;
}

/// 0xCD 0x01 as 10 coils, LSB first (6.11 example: coils 20..29 = 1011 0011 10).
const std::vector<bool> coils_cd01 = bits_of({1, 0, 1, 1, 0, 0, 1, 1, 1, 0});

struct RequestCase {
    const char* name;
    p::Request request;
    Bytes pdu;
};

const std::vector<RequestCase>& request_cases() {
    static const std::vector<RequestCase> cases = {
        {"6.1 FC01", p::ReadBitsRequest{0x01, 0x0013, 0x0013}, {0x01, 0x00, 0x13, 0x00, 0x13}},
        {"6.2 FC02", p::ReadBitsRequest{0x02, 0x00C4, 0x0016}, {0x02, 0x00, 0xC4, 0x00, 0x16}},
        {"6.3 FC03", p::ReadRegistersRequest{0x03, 0x006B, 3}, {0x03, 0x00, 0x6B, 0x00, 0x03}},
        {"6.4 FC04", p::ReadRegistersRequest{0x04, 0x0008, 1}, {0x04, 0x00, 0x08, 0x00, 0x01}},
        {"6.5 FC05 on", p::WriteSingleCoilRequest{0x00AC, true}, {0x05, 0x00, 0xAC, 0xFF, 0x00}},
        {"FC05 off", p::WriteSingleCoilRequest{0x00AC, false}, {0x05, 0x00, 0xAC, 0x00, 0x00}},
        {"6.6 FC06", p::WriteSingleRegisterRequest{0x0001, 0x0003}, {0x06, 0x00, 0x01, 0x00, 0x03}},
        {"6.7 FC07", p::ReadExceptionStatusRequest{}, {0x07}},
        {"6.11 FC0F", p::WriteMultipleCoilsRequest{0x0013, coils_cd01},
         {0x0F, 0x00, 0x13, 0x00, 0x0A, 0x02, 0xCD, 0x01}},
        {"6.12 FC10", p::WriteMultipleRegistersRequest{0x0001, {0x000A, 0x0102}},
         {0x10, 0x00, 0x01, 0x00, 0x02, 0x04, 0x00, 0x0A, 0x01, 0x02}},
        {"6.16 FC16", p::MaskWriteRegisterRequest{0x0004, 0x00F2, 0x0025}, {0x16, 0x00, 0x04, 0x00, 0xF2, 0x00, 0x25}},
        {"6.17 FC17", p::ReadWriteRegistersRequest{0x0003, 6, 0x000E, {0x00FF, 0x00FF, 0x00FF}},
         {0x17, 0x00, 0x03, 0x00, 0x06, 0x00, 0x0E, 0x00, 0x03, 0x06, 0x00, 0xFF, 0x00, 0xFF, 0x00, 0xFF}},
        {"6.21 FC2B opaque", p::OpaqueRequest{0x2B, {0x0E, 0x01, 0x00}}, {0x2B, 0x0E, 0x01, 0x00}},
        {"opaque without data", p::OpaqueRequest{0x41, {}}, {0x41}},
    };
    return cases;
}

struct ResponseCase {
    const char* name;
    p::Request request;
    p::Response response;
    Bytes pdu;
};

std::vector<bool> byte_bits(std::initializer_list<std::uint8_t> bytes) {
    std::vector<bool> bits;
    for (const auto b : bytes) {
        for (unsigned i = 0; i < 8; ++i) bits.push_back(((b >> i) & 1U) != 0);
    }
    return bits;
}

const std::vector<ResponseCase>& response_cases() {
    static const std::vector<ResponseCase> cases = {
        {"6.1 FC01", p::ReadBitsRequest{0x01, 0x0013, 0x0013},
         p::ReadBitsResponse{0x01, byte_bits({0xCD, 0x6B, 0x05})}, {0x01, 0x03, 0xCD, 0x6B, 0x05}},
        {"6.2 FC02", p::ReadBitsRequest{0x02, 0x00C4, 0x0016},
         p::ReadBitsResponse{0x02, byte_bits({0xAC, 0xDB, 0x35})}, {0x02, 0x03, 0xAC, 0xDB, 0x35}},
        {"6.3 FC03", p::ReadRegistersRequest{0x03, 0x006B, 3},
         p::ReadRegistersResponse{0x03, {0x022B, 0x0000, 0x0064}},
         {0x03, 0x06, 0x02, 0x2B, 0x00, 0x00, 0x00, 0x64}},
        {"6.4 FC04", p::ReadRegistersRequest{0x04, 0x0008, 1}, p::ReadRegistersResponse{0x04, {0x000A}},
         {0x04, 0x02, 0x00, 0x0A}},
        {"6.5 FC05", p::WriteSingleCoilRequest{0x00AC, true}, p::WriteSingleResponse{0x05, 0x00AC, 0xFF00},
         {0x05, 0x00, 0xAC, 0xFF, 0x00}},
        {"6.6 FC06", p::WriteSingleRegisterRequest{0x0001, 0x0003},
         p::WriteSingleResponse{0x06, 0x0001, 0x0003}, {0x06, 0x00, 0x01, 0x00, 0x03}},
        {"6.7 FC07", p::ReadExceptionStatusRequest{}, p::ReadExceptionStatusResponse{0x6D}, {0x07, 0x6D}},
        {"6.11 FC0F", p::WriteMultipleCoilsRequest{0x0013, coils_cd01},
         p::WriteMultipleResponse{0x0F, 0x0013, 10}, {0x0F, 0x00, 0x13, 0x00, 0x0A}},
        {"6.12 FC10", p::WriteMultipleRegistersRequest{0x0001, {0x000A, 0x0102}},
         p::WriteMultipleResponse{0x10, 0x0001, 2}, {0x10, 0x00, 0x01, 0x00, 0x02}},
        {"6.16 FC16", p::MaskWriteRegisterRequest{0x0004, 0x00F2, 0x0025},
         p::MaskWriteResponse{0x0004, 0x00F2, 0x0025}, {0x16, 0x00, 0x04, 0x00, 0xF2, 0x00, 0x25}},
        {"exception to FC16", p::MaskWriteRegisterRequest{0x0004, 0x00F2, 0x0025},
         p::ExceptionResponse{0x16, p::ExceptionCode::illegal_data_address}, {0x96, 0x02}},
        {"6.17 FC17", p::ReadWriteRegistersRequest{0x0003, 6, 0x000E, {0x00FF, 0x00FF, 0x00FF}},
         p::ReadRegistersResponse{0x17, {0x00FE, 0x0ACD, 0x0001, 0x0003, 0x000D, 0x00FF}},
         {0x17, 0x0C, 0x00, 0xFE, 0x0A, 0xCD, 0x00, 0x01, 0x00, 0x03, 0x00, 0x0D, 0x00, 0xFF}},
        {"7 exception to FC01", p::ReadBitsRequest{0x01, 0, 8},
         p::ExceptionResponse{0x01, p::ExceptionCode::illegal_function}, {0x81, 0x01}},
        {"exception to FC03", p::ReadRegistersRequest{0x03, 0x0611, 1},
         p::ExceptionResponse{0x03, p::ExceptionCode::illegal_data_address}, {0x83, 0x02}},
        {"exception to FC10", p::WriteMultipleRegistersRequest{0x0600, {1}},
         p::ExceptionResponse{0x10, p::ExceptionCode::server_device_busy}, {0x90, 0x06}},
        {"exception to FC17", p::ReadWriteRegistersRequest{0, 1, 0, {1}},
         p::ExceptionResponse{0x17, p::ExceptionCode::gateway_target_failed}, {0x97, 0x0B}},
        {"device-specific exception code", p::WriteSingleRegisterRequest{1, 2},
         p::ExceptionResponse{0x06, static_cast<p::ExceptionCode>(0x42)}, {0x86, 0x42}},
        {"opaque FC2B", p::OpaqueRequest{0x2B, {0x0E, 0x01, 0x00}},
         p::OpaqueResponse{0x2B, {0x0E, 0x01, 0x01, 0x00, 0x00, 0x00}},
         {0x2B, 0x0E, 0x01, 0x01, 0x00, 0x00, 0x00}},
        {"exception to opaque", p::OpaqueRequest{0x41, {0x01}},
         p::ExceptionResponse{0x41, p::ExceptionCode::illegal_function}, {0xC1, 0x01}},
    };
    return cases;
}

}  // namespace

TEST_CASE("pdu: requests encode and decode both ways") {
    for (const auto& c : request_cases()) {
        CAPTURE(std::string(c.name));
        CHECK(p::encode_request(c.request) == c.pdu);
        const auto decoded = p::decode_request(c.pdu);
        REQUIRE(decoded.complete());
        CHECK(decoded.consumed == c.pdu.size());
        CHECK(decoded.value == c.request);
        CHECK(p::function_of(c.request) == c.pdu[0]);
    }
}

TEST_CASE("pdu: a request truncated or extended by one byte is bad_length") {
    for (const auto& c : request_cases()) {
        if (std::holds_alternative<p::OpaqueRequest>(c.request)) continue;  // any length is valid
        CAPTURE(std::string(c.name));
        for (std::size_t len = 0; len < c.pdu.size(); ++len) {
            CAPTURE(len);
            const auto r = p::decode_request(ByteView(c.pdu).first(len));
            CHECK(r.malformed());
            CHECK(p::to_string(r.error) == "bad_length");
            CHECK(r.consumed == len);
        }
        Bytes longer = c.pdu;
        longer.push_back(0x00);
        const auto r = p::decode_request(longer);
        CHECK(r.malformed());
        CHECK(p::to_string(r.error) == "bad_length");
    }
}

TEST_CASE("pdu: request limits") {
    struct Case {
        const char* name;
        Bytes pdu;
        DecodeStatus status;
        DecodeError error;
    };
    constexpr auto ok = DecodeStatus::complete;
    constexpr auto bad = DecodeStatus::malformed;
    constexpr auto none = DecodeError::none;
    std::vector<Case> cases = {
        {"empty", {}, bad, DecodeError::bad_length},
        {"function 0", {0x00, 0x00, 0x00, 0x00, 0x01}, bad, DecodeError::bad_value},
        {"exception code as request", {0x83, 0x02}, bad, DecodeError::bad_value},
        {"FC01 count 0", {0x01, 0x00, 0x00, 0x00, 0x00}, bad, DecodeError::bad_value},
        {"FC01 count 2000", {0x01, 0x00, 0x00, 0x07, 0xD0}, ok, none},
        {"FC01 count 2001", {0x01, 0x00, 0x00, 0x07, 0xD1}, bad, DecodeError::bad_value},
        {"FC02 count 2001", {0x02, 0x00, 0x00, 0x07, 0xD1}, bad, DecodeError::bad_value},
        {"FC03 count 0", {0x03, 0x00, 0x00, 0x00, 0x00}, bad, DecodeError::bad_value},
        {"FC03 count 125", {0x03, 0x00, 0x00, 0x00, 0x7D}, ok, none},
        {"FC03 count 126", {0x03, 0x00, 0x00, 0x00, 0x7E}, bad, DecodeError::bad_value},
        {"FC04 count 126", {0x04, 0x00, 0x00, 0x00, 0x7E}, bad, DecodeError::bad_value},
        {"FC04 count 0xFFFF", {0x04, 0x00, 0x00, 0xFF, 0xFF}, bad, DecodeError::bad_value},
        {"FC05 value 0x1234", {0x05, 0x00, 0x01, 0x12, 0x34}, bad, DecodeError::bad_value},
        {"FC05 value 0x00FF", {0x05, 0x00, 0x01, 0x00, 0xFF}, bad, DecodeError::bad_value},
        {"FC05 value 0x0001", {0x05, 0x00, 0x01, 0x00, 0x01}, bad, DecodeError::bad_value},
        {"FC06 any value", {0x06, 0xFF, 0xFF, 0xFF, 0xFF}, ok, none},
        {"FC07 with data", {0x07, 0x00}, bad, DecodeError::bad_length},
        {"FC0F count 0", {0x0F, 0x00, 0x00, 0x00, 0x00, 0x00}, bad, DecodeError::bad_value},
        {"FC0F byte count short", {0x0F, 0x00, 0x13, 0x00, 0x0A, 0x01, 0xCD}, bad, DecodeError::bad_length},
        {"FC0F byte count long", {0x0F, 0x00, 0x13, 0x00, 0x0A, 0x03, 0xCD, 0x01, 0x00}, bad,
         DecodeError::bad_length},
        {"FC0F data missing", {0x0F, 0x00, 0x13, 0x00, 0x0A, 0x02, 0xCD}, bad, DecodeError::bad_length},
        {"FC10 count 0", {0x10, 0x00, 0x00, 0x00, 0x00, 0x00}, bad, DecodeError::bad_value},
        {"FC10 byte count odd", {0x10, 0x00, 0x01, 0x00, 0x02, 0x03, 0x00, 0x0A, 0x01}, bad,
         DecodeError::bad_length},
        {"FC10 one data byte extra", {0x10, 0x00, 0x01, 0x00, 0x01, 0x02, 0x00, 0x0A, 0x01}, bad,
         DecodeError::bad_length},
        {"FC17 read count 0", {0x17, 0, 0, 0, 0, 0, 0, 0, 1, 2, 0, 0}, bad, DecodeError::bad_value},
        {"FC17 write count 0", {0x17, 0, 0, 0, 1, 0, 0, 0, 0, 0}, bad, DecodeError::bad_value},
        {"FC17 read count 126", {0x17, 0, 0, 0, 0x7E, 0, 0, 0, 1, 2, 0, 0}, bad, DecodeError::bad_value},
        {"FC17 byte count mismatch", {0x17, 0, 0, 0, 1, 0, 0, 0, 1, 4, 0, 0}, bad, DecodeError::bad_length},
        {"opaque of max size", Bytes(p::max_pdu_size, 0x41), ok, none},
        {"opaque oversize", Bytes(p::max_pdu_size + 1, 0x41), bad, DecodeError::oversize},
    };
    // Largest multiple writes: FC0F 1968 coils (246 bytes), FC10 123 registers, FC17 121.
    auto multiple = [](std::uint8_t function, std::size_t count, std::size_t bytes) {
        Bytes pdu = {function, 0x00, 0x00, static_cast<std::uint8_t>(count >> 8),
                     static_cast<std::uint8_t>(count & 0xFF), static_cast<std::uint8_t>(bytes)};
        pdu.resize(pdu.size() + bytes, 0x5A);
        return pdu;
    };
    cases.push_back({"FC0F 1968 coils", multiple(0x0F, 1968, 246), ok, none});
    cases.push_back({"FC0F 1969 coils", multiple(0x0F, 1969, 247), bad, DecodeError::bad_value});
    cases.push_back({"FC10 123 registers", multiple(0x10, 123, 246), ok, none});
    cases.push_back({"FC10 124 registers do not fit a PDU", multiple(0x10, 124, 248), bad, DecodeError::oversize});
    cases.push_back({"FC10 count 124", multiple(0x10, 124, 2), bad, DecodeError::bad_value});
    auto read_write = [](std::size_t read, std::size_t write) {
        Bytes pdu = {0x17, 0x00, 0x00, 0x00, static_cast<std::uint8_t>(read), 0x00, 0x00, 0x00,
                     static_cast<std::uint8_t>(write), static_cast<std::uint8_t>(2 * write)};
        pdu.resize(pdu.size() + 2 * write, 0x11);
        return pdu;
    };
    cases.push_back({"FC17 read 125 write 121", read_write(125, 121), ok, none});
    cases.push_back({"FC17 write 122 does not fit a PDU", read_write(1, 122), bad, DecodeError::oversize});
    Bytes write_count_122 = read_write(1, 1);
    write_count_122[8] = 122;
    cases.push_back({"FC17 write count 122", write_count_122, bad, DecodeError::bad_value});

    for (const auto& c : cases) {
        CAPTURE(std::string(c.name));
        const auto r = p::decode_request(c.pdu);
        CHECK(r.status == c.status);
        CHECK(p::to_string(r.error) == p::to_string(c.error));
        CHECK(r.consumed == c.pdu.size());
        if (r.complete()) CHECK(p::encode_request(r.value) == c.pdu);
    }
}

TEST_CASE("pdu: encode_request rejects what breaks a protocol limit") {
    const std::vector<p::Request> invalid = {
        p::ReadBitsRequest{0x01, 0, 0},
        p::ReadBitsRequest{0x02, 0, 2001},
        p::ReadBitsRequest{0x03, 0, 1},  // not a bit read
        p::ReadRegistersRequest{0x03, 0, 0},
        p::ReadRegistersRequest{0x04, 0, 126},
        p::ReadRegistersRequest{0x01, 0, 1},  // not a register read
        p::WriteMultipleCoilsRequest{0, {}},
        p::WriteMultipleCoilsRequest{0, std::vector<bool>(1969, true)},
        p::WriteMultipleRegistersRequest{0, {}},
        p::WriteMultipleRegistersRequest{0, std::vector<std::uint16_t>(124, 1)},
        p::ReadWriteRegistersRequest{0, 0, 0, {1}},
        p::ReadWriteRegistersRequest{0, 126, 0, {1}},
        p::ReadWriteRegistersRequest{0, 1, 0, {}},
        p::ReadWriteRegistersRequest{0, 1, 0, std::vector<std::uint16_t>(122, 1)},
        p::OpaqueRequest{0x00, {}},
        p::OpaqueRequest{0x81, {}},
        p::OpaqueRequest{0x41, Bytes(p::max_pdu_size, 0)},
    };
    for (std::size_t i = 0; i < invalid.size(); ++i) {
        CAPTURE(i);
        CHECK_THROWS_AS((void)p::encode_request(invalid[i]), fieldbridge::core::InvalidArgument);
    }
    CHECK_THROWS_WITH((void)p::encode_request(p::ReadRegistersRequest{0x03, 0, 126}),
                      doctest::Contains("FC03 request: register count 126 is outside 1..125"));
    CHECK(p::encode_request(p::WriteMultipleCoilsRequest{0, std::vector<bool>(1968, true)}).size() == 252);
    CHECK(p::encode_request(p::WriteMultipleRegistersRequest{0, std::vector<std::uint16_t>(123, 1)}).size() ==
          252);
}

TEST_CASE("pdu: responses encode and decode both ways") {
    for (const auto& c : response_cases()) {
        CAPTURE(std::string(c.name));
        CHECK(p::encode_response(c.response) == c.pdu);
        const auto decoded = p::decode_response(c.pdu, c.request);
        REQUIRE(decoded.complete());
        CHECK(decoded.consumed == c.pdu.size());
        CHECK(decoded.value == c.response);
        // The predicted reply length is the PDU length from the first byte on.
        const auto predicted = p::predict_response_pdu_length(ByteView(c.pdu).first(1), c.request);
        if (std::holds_alternative<p::OpaqueResponse>(c.response)) {
            CHECK_FALSE(predicted.has_value());
        } else {
            REQUIRE(predicted.has_value());
            CHECK(predicted->status == DecodeStatus::complete);
            CHECK(predicted->length == c.pdu.size());
        }
    }
    CHECK(p::encode_exception(0x03, p::ExceptionCode::illegal_data_address) == Bytes{0x83, 0x02});
    CHECK_THROWS_AS((void)p::encode_exception(0x83, p::ExceptionCode::illegal_function), fieldbridge::core::InvalidArgument);
    CHECK_THROWS_AS((void)p::encode_exception(0x00, p::ExceptionCode::illegal_function), fieldbridge::core::InvalidArgument);
}

TEST_CASE("pdu: a response truncated at every length is never complete") {
    for (const auto& c : response_cases()) {
        if (std::holds_alternative<p::OpaqueResponse>(c.response)) continue;  // any length is valid
        CAPTURE(std::string(c.name));
        for (std::size_t len = 0; len < c.pdu.size(); ++len) {
            CAPTURE(len);
            const auto r = p::decode_response(ByteView(c.pdu).first(len), c.request);
            CHECK(r.malformed());
            CHECK(p::to_string(r.error) == "bad_length");
        }
        Bytes longer = c.pdu;
        longer.push_back(0x00);
        CHECK(p::decode_response(longer, c.request).error == DecodeError::bad_length);
    }
}

TEST_CASE("pdu: responses that do not answer the request") {
    const p::Request read3 = p::ReadRegistersRequest{0x03, 0x006B, 3};
    const p::Request read_bits = p::ReadBitsRequest{0x01, 0x0013, 0x0013};
    const p::Request write6 = p::WriteSingleRegisterRequest{0x0001, 0x0003};
    const p::Request coil = p::WriteSingleCoilRequest{0x00AC, true};
    const p::Request write16 = p::WriteMultipleRegistersRequest{0x0001, {0x000A, 0x0102}};
    const p::Request rw = p::ReadWriteRegistersRequest{0x0003, 2, 0x000E, {1}};
    struct Case {
        const char* name;
        p::Request request;
        Bytes pdu;
        DecodeError error;
    };
    const std::vector<Case> cases = {
        {"empty", read3, {}, DecodeError::bad_length},
        {"oversize", read3, Bytes(p::max_pdu_size + 1, 0x03), DecodeError::oversize},
        {"other function", read3, {0x04, 0x06, 0, 1, 0, 2, 0, 3}, DecodeError::wrong_function},
        {"exception of another function", read3, {0x84, 0x02}, DecodeError::wrong_function},
        {"exception without code", read3, {0x83}, DecodeError::bad_length},
        {"exception too long", read3, {0x83, 0x02, 0x00}, DecodeError::bad_length},
        {"byte count disagrees with size", read3, {0x03, 0x04, 0x00, 0x01}, DecodeError::bad_length},
        {"byte count 0", read3, {0x03, 0x00}, DecodeError::bad_length},
        {"fewer registers than asked", read3, {0x03, 0x02, 0x00, 0x0A}, DecodeError::unexpected_reply},
        {"more registers than asked", read3, {0x03, 0x08, 0, 1, 0, 2, 0, 3, 0, 4}, DecodeError::unexpected_reply},
        {"bits: byte count not for 19 bits", read_bits, {0x01, 0x02, 0xCD, 0x6B}, DecodeError::unexpected_reply},
        {"FC17 byte count for 3 registers", rw, {0x17, 0x06, 0, 1, 0, 2, 0, 3}, DecodeError::unexpected_reply},
        {"FC06 echo address differs", write6, {0x06, 0x00, 0x02, 0x00, 0x03}, DecodeError::unexpected_reply},
        {"FC06 echo value differs", write6, {0x06, 0x00, 0x01, 0x00, 0x04}, DecodeError::unexpected_reply},
        {"FC05 echo OFF for ON", coil, {0x05, 0x00, 0xAC, 0x00, 0x00}, DecodeError::unexpected_reply},
        {"FC05 echo bad value", coil, {0x05, 0x00, 0xAC, 0x12, 0x34}, DecodeError::unexpected_reply},
        {"FC10 echo count differs", write16, {0x10, 0x00, 0x01, 0x00, 0x03}, DecodeError::unexpected_reply},
        {"FC10 echo address differs", write16, {0x10, 0x00, 0x00, 0x00, 0x02}, DecodeError::unexpected_reply},
        {"FC16 echo or-mask differs", p::MaskWriteRegisterRequest{0x0004, 0x00F2, 0x0025},
         {0x16, 0x00, 0x04, 0x00, 0xF2, 0x00, 0x26}, DecodeError::unexpected_reply},
        {"FC07 reply too long", p::ReadExceptionStatusRequest{}, {0x07, 0x01, 0x02}, DecodeError::bad_length},
    };
    for (const auto& c : cases) {
        CAPTURE(std::string(c.name));
        const auto r = p::decode_response(c.pdu, c.request);
        CHECK(r.malformed());
        CHECK(p::to_string(r.error) == p::to_string(c.error));
        CHECK(r.consumed == c.pdu.size());
    }
}

TEST_CASE("pdu: encode_response rejects responses no device may send") {
    const std::vector<p::Response> invalid = {
        p::ReadBitsResponse{0x03, byte_bits({0x01})},
        p::ReadBitsResponse{0x01, {}},
        p::ReadRegistersResponse{0x01, {1}},
        p::ReadRegistersResponse{0x03, {}},
        p::ReadRegistersResponse{0x03, std::vector<std::uint16_t>(126, 0)},
        p::WriteSingleResponse{0x10, 0, 0},
        p::WriteMultipleResponse{0x06, 0, 1},
        p::ExceptionResponse{0x80, p::ExceptionCode::illegal_function},
        p::OpaqueResponse{0x00, {}},
        p::OpaqueResponse{0x41, Bytes(p::max_pdu_size, 0)},
    };
    for (std::size_t i = 0; i < invalid.size(); ++i) {
        CAPTURE(i);
        CHECK_THROWS_AS((void)p::encode_response(invalid[i]), fieldbridge::core::InvalidArgument);
    }
}

TEST_CASE("pdu: request length prediction at every prefix") {
    for (const auto& c : request_cases()) {
        CAPTURE(std::string(c.name));
        const bool opaque = std::holds_alternative<p::OpaqueRequest>(c.request);
        for (std::size_t len = 0; len <= c.pdu.size(); ++len) {
            CAPTURE(len);
            const auto predicted = p::predict_request_pdu_length(ByteView(c.pdu).first(len));
            if (len == 0) {
                REQUIRE(predicted.has_value());
                CHECK(predicted->status == DecodeStatus::need_more);
                continue;
            }
            if (opaque) {
                CHECK_FALSE(predicted.has_value());
                continue;
            }
            REQUIRE(predicted.has_value());
            if (predicted->status == DecodeStatus::complete) {
                CHECK(predicted->length == c.pdu.size());
            } else {
                CHECK(predicted->status == DecodeStatus::need_more);
            }
        }
        if (!opaque) CHECK(p::predict_request_pdu_length(c.pdu)->status == DecodeStatus::complete);
    }
    // The multiple writes are known once the byte count is there (libmodbus' meta length).
    CHECK(p::predict_request_pdu_length(Bytes{0x10, 0, 0, 0, 1})->status == DecodeStatus::need_more);
    CHECK(p::predict_request_pdu_length(Bytes{0x10, 0, 0, 0, 1, 2})->length == 8);
    CHECK(p::predict_request_pdu_length(Bytes{0x0F, 0, 0, 0, 9, 2})->length == 8);
    CHECK(p::predict_request_pdu_length(Bytes{0x17, 0, 0, 0, 1, 0, 0, 0, 1})->status == DecodeStatus::need_more);
    CHECK(p::predict_request_pdu_length(Bytes{0x17, 0, 0, 0, 1, 0, 0, 0, 1, 2})->length == 12);
}

TEST_CASE("pdu: response length prediction") {
    const p::Request read_bits = p::ReadBitsRequest{0x02, 0, 9};
    const p::Request read_regs = p::ReadRegistersRequest{0x04, 0, 125};
    const p::Request opaque = p::OpaqueRequest{0x41, {}};
    CHECK(p::predict_response_pdu_length({}, read_regs)->status == DecodeStatus::need_more);
    CHECK(p::predict_response_pdu_length(Bytes{0x02}, read_bits)->length == 4);
    CHECK(p::predict_response_pdu_length(Bytes{0x04}, read_regs)->length == 252);
    CHECK(p::predict_response_pdu_length(Bytes{0x84}, read_regs)->length == 2);
    CHECK(p::predict_response_pdu_length(Bytes{0x03}, read_regs)->status == DecodeStatus::malformed);
    CHECK(p::predict_response_pdu_length(Bytes{0x83}, read_regs)->status == DecodeStatus::malformed);
    CHECK_FALSE(p::predict_response_pdu_length(Bytes{0x41}, opaque).has_value());
    CHECK(p::predict_response_pdu_length(Bytes{0xC1}, opaque)->length == 2);
    CHECK(p::predict_response_pdu_length(Bytes{0x42}, opaque)->status == DecodeStatus::malformed);
}

TEST_CASE("pdu: is_write") {
    for (const int read : {0x01, 0x02, 0x03, 0x04, 0x07, 0x0B, 0x0C, 0x11, 0x14, 0x18, 0x2B, 0x83}) {
        CAPTURE(read);
        CHECK_FALSE(p::is_write(fieldbridge::core::FunctionCode{static_cast<std::uint8_t>(read)}));
    }
    for (const int write : {0x05, 0x06, 0x08, 0x0F, 0x10, 0x15, 0x16, 0x17, 0x41, 0x64, 0x90}) {
        CAPTURE(write);
        CHECK(p::is_write(fieldbridge::core::FunctionCode{static_cast<std::uint8_t>(write)}));
    }
}

TEST_CASE("pdu: fuzz - decoders never crash, complete results re-encode") {
    std::mt19937 rng(20240601U);
    std::vector<Bytes> seeds;
    std::vector<p::Request> requests;
    for (const auto& c : request_cases()) {
        seeds.push_back(c.pdu);
        requests.push_back(c.request);
    }
    for (const auto& c : response_cases()) seeds.push_back(c.pdu);
    int completes = 0;
    for (int round = 0; round < 20000; ++round) {
        Bytes pdu;
        if (round % 2 == 0) {
            // Mutate a valid PDU: flip, insert, drop or truncate bytes.
            pdu = seeds[rng() % seeds.size()];
            const auto edits = 1 + rng() % 3;
            for (std::size_t e = 0; e < edits; ++e) {
                const std::size_t at = pdu.empty() ? 0 : rng() % pdu.size();
                switch (rng() % 4) {
                    case 0: if (!pdu.empty()) pdu[at] = static_cast<std::uint8_t>(rng()); break;
                    case 1: pdu.insert(pdu.begin() + static_cast<std::ptrdiff_t>(at), static_cast<std::uint8_t>(rng())); break;
                    case 2: if (!pdu.empty()) pdu.erase(pdu.begin() + static_cast<std::ptrdiff_t>(at)); break;
                    default: pdu.resize(at); break;
                }
            }
        } else {
            pdu.resize(rng() % 260);
            for (auto& b : pdu) b = static_cast<std::uint8_t>(rng());
            if (!pdu.empty() && rng() % 2 == 0) pdu[0] = static_cast<std::uint8_t>(rng() % 0x18);
        }
        const auto request = p::decode_request(pdu);
        if (request.consumed > pdu.size()) FAIL_CHECK("decode_request consumed too much: " << hex(pdu));
        if (request.complete()) {
            ++completes;
            const auto again = p::decode_request(p::encode_request(request.value));
            if (!again.complete() || !(again.value == request.value)) {
                FAIL_CHECK("decoded request does not survive re-encoding: " << hex(pdu));
            }
        }
        const auto& against = requests[rng() % requests.size()];
        const auto response = p::decode_response(pdu, against);
        if (response.consumed > pdu.size()) FAIL_CHECK("decode_response consumed too much: " << hex(pdu));
        if (response.complete()) {
            ++completes;
            const auto again = p::decode_response(p::encode_response(response.value), against);
            if (!again.complete() || !(again.value == response.value)) {
                FAIL_CHECK("decoded response does not survive re-encoding: " << hex(pdu));
            }
        }
        (void)p::predict_request_pdu_length(pdu);
        (void)p::predict_response_pdu_length(pdu, against);
    }
    CHECK(completes > 1000);  // the mutations do reach the decoders' success paths
}

TEST_CASE("pdu: FC16 mask write's result (Modbus Application Protocol 6.16's example)") {
    // Current 0x0012, AND 0x00F2, OR 0x0025: 0x0017.
    CHECK(p::MaskWriteRegisterRequest{4, 0x00F2, 0x0025}.applied_to(0x0012) == 0x0017);
    CHECK(p::MaskWriteRegisterRequest{4, 0xFFFF, 0x1234}.applied_to(0xABCD) == 0xABCD);  // AND all: unchanged
    CHECK(p::MaskWriteRegisterRequest{4, 0x0000, 0x1234}.applied_to(0xABCD) == 0x1234);  // AND none: the OR mask
    CHECK(p::decode_request(Bytes{0x16, 0x00, 0x04, 0x00, 0xF2, 0x00}).error == DecodeError::bad_length);
    CHECK(p::decode_request(Bytes{0x16, 0x00, 0x04, 0x00, 0xF2, 0x00, 0x25, 0x00}).error == DecodeError::bad_length);
}
