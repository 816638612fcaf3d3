// The scan's identification sequence (scan/device_probe.hpp): which reads it sends
// per address and what it concludes, driven with scripted replies.

#include <doctest/doctest.h>

#include <optional>
#include <string>
#include <vector>

#include "protocol/crc16.hpp"
#include "scan/device_probe.hpp"

namespace fieldbridge::scan {
namespace {

using protocol::ExceptionCode;
using protocol::ReadRegistersRequest;
using protocol::Response;
namespace fc = protocol::fc;

Response values(std::vector<std::uint16_t> v) { return protocol::ReadRegistersResponse{fc::read_holding_registers, std::move(v)}; }
Response exception(ExceptionCode code) { return protocol::ExceptionResponse{fc::read_holding_registers, code}; }

ReadRegistersRequest expect_read(const ModbusProbe& probe) {
    const auto next = probe.next();
    REQUIRE(next.has_value());
    const auto* read = std::get_if<ReadRegistersRequest>(&*next);
    REQUIRE(read != nullptr);
    CHECK(read->function == fc::read_holding_registers);
    return *read;
}

/// Runs @p probe with @p replies in order and returns the requests it sent.
std::vector<ReadRegistersRequest> run(ModbusProbe& probe, const std::vector<std::optional<Response>>& replies) {
    std::vector<ReadRegistersRequest> sent;
    for (const auto& reply : replies) {
        REQUIRE_FALSE(probe.finished());
        sent.push_back(expect_read(probe));
        probe.on_reply(reply);
    }
    CHECK(probe.finished());
    CHECK_FALSE(probe.next().has_value());
    return sent;
}

TEST_CASE("no reply to the presence read: nothing there, one request only") {
    ModbusProbe probe(7);
    const auto sent = run(probe, {std::nullopt});
    REQUIRE(sent.size() == 1);
    CHECK(sent[0] == ReadRegistersRequest{fc::read_holding_registers, 0x0000, 1});
    CHECK_FALSE(probe.result().has_value());
}

TEST_CASE("an XEG: exception at 0x0000, a listed model code at 0x0600") {
    ModbusProbe probe(2);
    const auto sent = run(probe, {exception(ExceptionCode::illegal_data_address), values({0x0A20})});
    CHECK(sent[1] == ReadRegistersRequest{fc::read_holding_registers, 0x0600, 1});
    REQUIRE(probe.result().has_value());
    CHECK(probe.result()->address == 2);
    CHECK(probe.result()->type == engine::DeviceType::hiwin_xeg);
    CHECK(probe.result()->detail == "XEG-32 (model 0x0A20)");
}

TEST_CASE("a model code the XEG manual does not list is not an XEG") {
    ModbusProbe probe(2);
    const auto sent = run(probe, {values({0}), values({0x1234}), exception(ExceptionCode::illegal_data_address),
                                  exception(ExceptionCode::illegal_data_address)});
    REQUIRE(probe.result().has_value());
    CHECK(probe.result()->type == engine::DeviceType::modbus);
    CHECK(probe.result()->holding_zero_readable);
}

TEST_CASE("a WTEC-485 in RTU mode: 0x0303 reads its own address") {
    ModbusProbe probe(9);
    const auto sent = run(probe, {exception(ExceptionCode::illegal_data_address),
                                  exception(ExceptionCode::illegal_data_address), values({9})});
    CHECK(sent[2] == ReadRegistersRequest{fc::read_holding_registers, 0x0303, 1});
    REQUIRE(probe.result().has_value());
    CHECK(probe.result()->type == engine::DeviceType::wtec_rtu);
    CHECK(probe.result()->detail == "device ID register 0x0303 reads 9");
}

TEST_CASE("0x0303 reading another number is not a WTEC; two registers at 0x0207 are an EXCD203MB") {
    ModbusProbe probe(3);
    const auto sent = run(probe, {values({1}), exception(ExceptionCode::illegal_data_address), values({0}),
                                  values({0, 120})});
    CHECK(sent[3] == ReadRegistersRequest{fc::read_holding_registers, 0x0207, 2});
    REQUIRE(probe.result().has_value());
    CHECK(probe.result()->type == engine::DeviceType::excd203mb);
    CHECK(probe.result()->detail == "ver (0x0207-0x0208) reads 120");
}

TEST_CASE("a device that stops answering after the presence read is a generic Modbus device") {
    ModbusProbe probe(40);
    run(probe, {exception(ExceptionCode::illegal_function), std::nullopt, std::nullopt, std::nullopt});
    REQUIRE(probe.result().has_value());
    CHECK(probe.result()->type == engine::DeviceType::modbus);
    CHECK_FALSE(probe.result()->holding_zero_readable);
    CHECK(probe.result()->detail == "answers FC03 at 0x0000 with an exception; not an XEG, WTEC-485 or EXCD203MB");
}

TEST_CASE("a generic Modbus device whose first holding register reads a value") {
    ModbusProbe probe(41);
    const auto sent = run(probe, {values({7}), std::nullopt, std::nullopt, std::nullopt});
    CHECK(sent[0] == ReadRegistersRequest{fc::read_holding_registers, 0x0000, 1});
    REQUIRE(probe.result().has_value());
    CHECK(probe.result()->type == engine::DeviceType::modbus);
    CHECK(probe.result()->holding_zero_readable);
    CHECK(probe.result()->detail == "answers FC03 at 0x0000; not an XEG, WTEC-485 or EXCD203MB");
}

TEST_CASE("no built-in type: the definitions' identify reads in order; the first that matches names the device") {
    core::IdentifyRead meter_read;
    meter_read.table = core::RegisterTable::input;
    meter_read.address = 0x0100;
    meter_read.count = 2;
    meter_read.expect = {0x4D31, 0x0002};
    core::IdentifyRead thermostat_read;
    thermostat_read.address = 0x0020;  // holding, one register, any value
    const std::vector<DefinitionIdentify> definitions{{"acme-meter", meter_read}, {"acme-thermostat", thermostat_read}};
    // Presence answered, then no XEG, WTEC or EXCD203MB: the definitions come next.
    const auto past_built_in_types = [](ModbusProbe& probe) {
        for (const auto& reply : std::vector<std::optional<Response>>{values({1}), std::nullopt, std::nullopt, std::nullopt}) {
            (void)expect_read(probe);
            probe.on_reply(reply);
        }
        REQUIRE_FALSE(probe.finished());
    };

    SUBCASE("the second matches: FC04 of the first, then FC03 of the second") {
        ModbusProbe probe(9, definitions);
        past_built_in_types(probe);
        auto next = probe.next();
        REQUIRE(next.has_value());
        CHECK(std::get<ReadRegistersRequest>(*next) == ReadRegistersRequest{fc::read_input_registers, 0x0100, 2});
        probe.on_reply(values({0x4D31, 0x0003}));  // not the expected values
        next = probe.next();
        REQUIRE(next.has_value());
        CHECK(std::get<ReadRegistersRequest>(*next) == ReadRegistersRequest{fc::read_holding_registers, 0x0020, 1});
        probe.on_reply(values({0x1234}));  // no expect: any answer
        REQUIRE(probe.finished());
        REQUIRE(probe.result().has_value());
        CHECK(probe.result()->type == engine::DeviceType::modbus);
        CHECK(probe.result()->definition == "acme-thermostat");
        CHECK(probe.result()->detail == "device definition acme-thermostat: its identify read (holding 0x0020) is answered");
    }
    SUBCASE("the first matches its expected values") {
        ModbusProbe probe(9, definitions);
        past_built_in_types(probe);
        probe.on_reply(values({0x4D31, 0x0002}));
        REQUIRE(probe.result().has_value());
        CHECK(probe.result()->definition == "acme-meter");
        CHECK(probe.result()->detail ==
              "device definition acme-meter: its identify read (input 0x0100-0x0101) reads the expected values");
    }
    SUBCASE("none matches (an exception, no reply): a generic device") {
        ModbusProbe probe(9, definitions);
        past_built_in_types(probe);
        probe.on_reply(exception(ExceptionCode::illegal_data_address));
        probe.on_reply(std::nullopt);
        REQUIRE(probe.finished());
        CHECK(probe.result()->definition.empty());
        CHECK(probe.result()->detail ==
              "answers FC03 at 0x0000; not an XEG, WTEC-485 or EXCD203MB, nor a device definition's identify read");
    }
    SUBCASE("a built-in type is found first; the definitions are not read") {
        ModbusProbe probe(2, definitions);
        run(probe, {exception(ExceptionCode::illegal_data_address), values({0x0A20})});
        CHECK(probe.result()->type == engine::DeviceType::hiwin_xeg);
        CHECK(probe.result()->definition.empty());
    }
}

TEST_CASE("on_reply after the probe finished is a caller error") {
    ModbusProbe probe(1);
    probe.on_reply(std::nullopt);
    CHECK_THROWS_AS(probe.on_reply(std::nullopt), std::logic_error);
}

std::string frame(const std::string& body) {
    const auto crc = protocol::crc16_modbus(protocol::ByteView(reinterpret_cast<const std::uint8_t*>(body.data()), body.size()));
    constexpr const char* digits = "0123456789ABCDEF";
    std::string out = body;
    for (int shift = 12; shift >= 0; shift -= 4) out.push_back(digits[(crc >> shift) & 0xF]);
    return out + "\r\n";
}

protocol::Bytes bytes(const std::string& text) { return protocol::Bytes(text.begin(), text.end()); }

TEST_CASE("parse_stations: the manual's `$` reply, several stations, noise and bad frames") {
    // Seed 003 command 2: ">01$01E2DF", ">02$02A79F".
    CHECK(parse_stations(bytes(">01$01E2DF\r\n")) == std::vector<std::uint8_t>{1});
    CHECK(parse_stations(bytes(">02$02A79F\r\n>01$01E2DF\r\n")) == std::vector<std::uint8_t>{1, 2});
    CHECK(parse_stations(bytes("\x01\xFFgarbage" + frame(">FD$FD"))) == std::vector<std::uint8_t>{0xFD});
    // A bad CRC, a station that differs from the frame address, another command, a
    // station 00, a duplicate, and an unfinished frame at the end.
    const std::string rx = ">01$01E2D0\r\n" + frame(">03$04") + frame(">05A") + frame(">00$00") + frame(">07$07") +
                           frame(">07$07") + ">09$0";
    CHECK(parse_stations(bytes(rx)) == std::vector<std::uint8_t>{7});
    CHECK(parse_stations({}).empty());
}

}  // namespace
}  // namespace fieldbridge::scan
