#include "sim_test_support.hpp"

#include <doctest/doctest.h>

#include <stdexcept>
#include <vector>

#include "protocol/crc16.hpp"
#include "protocol/modbus_pdu.hpp"
#include "protocol/rtu_frame.hpp"

namespace fieldbridge::test {
namespace {

int nibble(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    throw std::invalid_argument(std::string("not a hex digit: ") + c);
}

}  // namespace

protocol::Bytes hex(std::string_view text) {
    protocol::Bytes out;
    int high = -1;
    for (const char c : text) {
        if (c == ' ' || c == '\n') continue;
        const int v = nibble(c);
        if (high < 0) {
            high = v;
        } else {
            out.push_back(static_cast<std::uint8_t>((high << 4) | v));
            high = -1;
        }
    }
    if (high >= 0) throw std::invalid_argument("odd number of hex digits in \"" + std::string(text) + "\"");
    return out;
}

std::string hex_of(protocol::ByteView bytes) {
    static constexpr char digits[] = "0123456789ABCDEF";
    std::string out;
    for (const auto b : bytes) {
        if (!out.empty()) out += ' ';
        out += digits[b >> 4];
        out += digits[b & 0x0F];
    }
    return out;
}

protocol::Bytes rtu(std::string_view address_and_pdu_hex) {
    const protocol::Bytes body = hex(address_and_pdu_hex);
    return protocol::encode_rtu(body.at(0), protocol::ByteView(body).subspan(1));
}

protocol::Bytes ascii(std::string_view body) {
    protocol::Bytes out(body.begin(), body.end());
    out.push_back('\r');
    out.push_back('\n');
    return out;
}

std::string ascii_text(protocol::ByteView bytes) {
    std::string text(bytes.begin(), bytes.end());
    if (text.size() >= 2 && text.substr(text.size() - 2) == "\r\n") text.resize(text.size() - 2);
    return text;
}

std::string exchange(sim::BusDevice& device, const protocol::Bytes& request, Clock::time_point now) {
    device.advance(now);
    const auto reply = device.on_frame(request, now);
    return reply ? hex_of(*reply) : std::string{};
}

std::string exchange_ascii(sim::BusDevice& device, std::string_view body, Clock::time_point now) {
    device.advance(now);
    const auto reply = device.on_frame(ascii(body), now);
    if (!reply) return {};
    const std::string text(reply->begin(), reply->end());
    CHECK_MESSAGE(text.size() >= 2, "reply too short: " << text);
    CHECK_MESSAGE(text.substr(text.size() - 2) == "\r\n", "reply does not end in CR LF: " << text);
    return ascii_text(*reply);
}

std::vector<std::uint16_t> read_registers(sim::BusDevice& device, std::uint8_t unit,
                                          std::uint8_t function, std::uint16_t address,
                                          std::uint16_t count, Clock::time_point now) {
    const protocol::ReadRegistersRequest request{function, address, count};
    const protocol::Bytes pdu = protocol::encode_request(request);
    const auto reply = device.on_frame(protocol::encode_rtu(unit, pdu), now);
    REQUIRE_MESSAGE(reply.has_value(), "no reply to a read of " << address);
    const auto frame = protocol::decode_rtu(*reply);
    REQUIRE(frame.complete());
    const auto response = protocol::decode_response(frame.value.pdu, request);
    REQUIRE_MESSAGE(response.complete(), "bad reply " << hex_of(*reply));
    const auto* values = std::get_if<protocol::ReadRegistersResponse>(&response.value);
    REQUIRE_MESSAGE(values != nullptr, "not a read reply: " << hex_of(*reply));
    return values->values;
}

std::string write_registers(sim::BusDevice& device, std::uint8_t unit, std::uint16_t address,
                            std::vector<std::uint16_t> values, Clock::time_point now, bool single) {
    protocol::Request request;
    if (single) {
        request = protocol::WriteSingleRegisterRequest{address, values.at(0)};
    } else {
        request = protocol::WriteMultipleRegistersRequest{address, std::move(values)};
    }
    const auto reply = device.on_frame(protocol::encode_rtu(unit, protocol::encode_request(request)), now);
    if (!reply) return {};
    const auto frame = protocol::decode_rtu(*reply);
    REQUIRE(frame.complete());
    return hex_of(frame.value.pdu);
}

}  // namespace fieldbridge::test
