#include <doctest/doctest.h>

#include <cstdint>
#include <random>
#include <string_view>
#include <vector>

#include "protocol/crc16.hpp"

namespace {

using fieldbridge::protocol::Bytes;
using fieldbridge::protocol::ByteView;
using fieldbridge::protocol::crc16_modbus;
using fieldbridge::protocol::crc16_modbus_init;
using fieldbridge::protocol::crc16_modbus_update;

/// Bit-at-a-time reference (Modbus over Serial Line V1.02, 6.2.2, the algorithm in
/// prose), to check the table-driven implementation against.
std::uint16_t reference_crc(ByteView data) {
    unsigned crc = 0xFFFF;
    for (const std::uint8_t byte : data) {
        crc ^= byte;
        for (int bit = 0; bit < 8; ++bit) crc = (crc & 1U) != 0 ? (crc >> 1) ^ 0xA001U : crc >> 1;
    }
    return static_cast<std::uint16_t>(crc);
}

Bytes text(std::string_view s) { return Bytes(s.begin(), s.end()); }

}  // namespace

TEST_CASE("crc16: catalogue check value and empty input") {
    // CRC-16/MODBUS in the CRC catalogue: check = 0x4B37 over "123456789".
    CHECK(crc16_modbus(text("123456789")) == 0x4B37);
    CHECK(crc16_modbus({}) == crc16_modbus_init);
    CHECK(crc16_modbus(Bytes{0x00}) == 0x40BF);
    CHECK(crc16_modbus(Bytes{0xFF}) == 0x00FF);
}

TEST_CASE("crc16: frames from the manuals (CRC sent low byte first)") {
    struct Case {
        Bytes body;
        std::uint16_t crc;
    };
    const std::vector<Case> cases = {
        {{0x02, 0x03, 0x06, 0x00, 0x00, 0x01}, 0xB184},                    // wire 84 B1
        {{0x02, 0x07}, 0x1241},                                           // wire 41 12
        {{0x02, 0x86, 0x02}, 0xA133},                                     // wire 33 A1
        {{0x01, 0x06, 0x01, 0x00, 0x00, 0x01}, 0xF649},                   // wire 49 F6
        {{0x02, 0x10, 0x06, 0x00, 0x00, 0x01, 0x02, 0x0A, 0x20}, 0xD8D3}, // wire D3 D8
    };
    for (const auto& c : cases) {
        CAPTURE(c.crc);
        CHECK(crc16_modbus(c.body) == c.crc);
        Bytes adu = c.body;
        adu.push_back(static_cast<std::uint8_t>(c.crc & 0xFF));
        adu.push_back(static_cast<std::uint8_t>(c.crc >> 8));
        // Residue: the CRC over a frame including its own CRC is 0.
        CHECK(crc16_modbus(adu) == 0);
    }
    // WTEC ASCII: CRC over the characters from '>' through the data (seed 003, 1.2).
    CHECK(crc16_modbus(text(">01A")) == 0x63D8);
}

TEST_CASE("crc16: table-driven equals the bitwise reference; update is incremental") {
    std::mt19937 rng(0xC0FFEEU);
    for (int round = 0; round < 500; ++round) {
        Bytes data(rng() % 300);
        for (auto& b : data) b = static_cast<std::uint8_t>(rng());
        const std::uint16_t whole = crc16_modbus(data);
        REQUIRE(whole == reference_crc(data));
        const std::size_t split = data.empty() ? 0 : rng() % data.size();
        const ByteView view(data);
        CHECK(crc16_modbus_update(crc16_modbus(view.first(split)), view.subspan(split)) == whole);
    }
}

TEST_CASE("crc16: every single-bit error is detected") {
    const Bytes frame = {0x02, 0x04, 0x08, 0x00, 0x03, 0x00, 0x00, 0x00, 0x01, 0x03, 0x74, 0x49, 0x5E};
    REQUIRE(crc16_modbus(frame) == 0);
    for (std::size_t i = 0; i < frame.size(); ++i) {
        for (unsigned bit = 0; bit < 8; ++bit) {
            Bytes corrupted = frame;
            corrupted[i] = static_cast<std::uint8_t>(corrupted[i] ^ (1U << bit));
            CAPTURE(i);
            CAPTURE(bit);
            CHECK(crc16_modbus(corrupted) != 0);
        }
    }
}
