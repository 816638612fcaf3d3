// The generic `modbus` device of the simulator: every holding register answers FC03
// with its own address until written, FC04 likewise, FC06/FC16 write, the rest 01.
#include <doctest/doctest.h>

#include <initializer_list>
#include <optional>
#include <stdexcept>

#include "models/device_factory.hpp"
#include "protocol/rtu_frame.hpp"

namespace fieldbridge::sim {
namespace {

protocol::Bytes adu(std::uint8_t address, std::initializer_list<std::uint8_t> pdu) {
    const protocol::Bytes bytes(pdu);
    return protocol::encode_rtu(address, bytes);
}

std::optional<protocol::Bytes> send(BusDevice& device, const protocol::Bytes& frame) {
    return device.on_frame(frame, Clock::now());
}

}  // namespace

TEST_CASE("generic modbus: FC03 anywhere answers the registers' own addresses") {
    const auto device = make_device("modbus", 7, DeviceOptions{});
    CHECK(send(*device, adu(7, {0x03, 0x01, 0x23, 0x00, 0x02})) == adu(7, {0x03, 0x04, 0x01, 0x23, 0x01, 0x24}));
    CHECK(send(*device, adu(7, {0x04, 0xFF, 0xFE, 0x00, 0x02})) == adu(7, {0x04, 0x04, 0xFF, 0xFE, 0xFF, 0xFF}));
    CHECK(send(*device, adu(8, {0x03, 0x00, 0x00, 0x00, 0x01})) == std::nullopt);  // not addressed
}

TEST_CASE("generic modbus: writes are read back; a read past 0xFFFF is 02, other codes 01") {
    const auto device = make_device("modbus", 1, DeviceOptions{});
    CHECK(send(*device, adu(1, {0x06, 0x00, 0x10, 0xBE, 0xEF})) == adu(1, {0x06, 0x00, 0x10, 0xBE, 0xEF}));
    CHECK(send(*device, adu(1, {0x10, 0x00, 0x11, 0x00, 0x01, 0x02, 0x12, 0x34})) ==
          adu(1, {0x10, 0x00, 0x11, 0x00, 0x01}));
    CHECK(send(*device, adu(1, {0x03, 0x00, 0x10, 0x00, 0x02})) == adu(1, {0x03, 0x04, 0xBE, 0xEF, 0x12, 0x34}));
    CHECK(send(*device, adu(1, {0x03, 0xFF, 0xFF, 0x00, 0x02})) == adu(1, {0x83, 0x02}));
    CHECK(send(*device, adu(1, {0x01, 0x00, 0x00, 0x00, 0x01})) == adu(1, {0x81, 0x01}));
    CHECK(send(*device, adu(0, {0x06, 0x00, 0x20, 0x00, 0x05})) == std::nullopt);  // broadcast: acts, silent
    CHECK(send(*device, adu(1, {0x03, 0x00, 0x20, 0x00, 0x01})) == adu(1, {0x03, 0x02, 0x00, 0x05}));
}

TEST_CASE("generic modbus: addresses outside 1-247 are refused") {
    CHECK_THROWS_AS(static_cast<void>(make_device("modbus", 0, DeviceOptions{})), std::invalid_argument);
    CHECK_THROWS_AS(static_cast<void>(make_device("modbus", 248, DeviceOptions{})), std::invalid_argument);
}

}  // namespace fieldbridge::sim
