// A device simulated from a definition: exactly its points' and blocks' registers
// (02 elsewhere), FC01-06/15/16/22, and values set by point name in engineering
// units or by raw register through its control commands.
#include <doctest/doctest.h>

#include <initializer_list>
#include <optional>
#include <stdexcept>

#include "models/device_factory.hpp"
#include "models/point_text.hpp"
#include "protocol/rtu_frame.hpp"

namespace fieldbridge::sim {
namespace {

using core::PointDef;
using core::PointType;
using core::RegisterTable;

protocol::Bytes adu(std::uint8_t address, std::initializer_list<std::uint8_t> pdu) {
    const protocol::Bytes bytes(pdu);
    return protocol::encode_rtu(address, bytes);
}

std::optional<protocol::Bytes> send(BusDevice& device, const protocol::Bytes& frame) {
    return device.on_frame(frame, Clock::now());
}

PointDef point(std::string name, RegisterTable table, std::uint16_t address, PointType type = PointType::uint16) {
    PointDef p;
    p.name = std::move(name);
    p.table = table;
    p.address = address;
    p.type = type;
    return p;
}

/// A thermostat-like device: float32 temperature (input 0-1, low word first), int32
/// counter (input 2-3), a status word with bits (input 4), an enum mode and a scaled
/// setpoint (holding 0x10, 0x11), a name (holding 0x20-0x21), a coil; and a block of
/// 2 holding registers at 0x100.
std::shared_ptr<const DefinitionSpec> thermostat() {
    auto spec = std::make_shared<DefinitionSpec>();
    spec->name = "thermostat";
    auto temperature = point("temperature", RegisterTable::input, 0, PointType::float32);
    temperature.word_order = core::WordOrder::low_first;
    auto counter = point("runtime", RegisterTable::input, 2, PointType::int32);
    auto fault = point("sensor_fault", RegisterTable::input, 4, PointType::boolean);
    fault.bit = 3;
    auto mode = point("mode", RegisterTable::holding, 0x10);
    mode.labels = {{0, "off"}, {1, "heat"}, {2, "cool"}};
    auto setpoint = point("setpoint", RegisterTable::holding, 0x11, PointType::int16);
    setpoint.scale = 0.1;
    setpoint.offset = 0;
    auto label = point("label", RegisterTable::holding, 0x20, PointType::string);
    label.count = 2;
    auto little = point("little", RegisterTable::holding, 0x30, PointType::uint32);
    little.byte_order = core::ByteOrder::little;
    spec->points.points = {temperature, counter,  fault, point("status", RegisterTable::input, 4), mode, setpoint,
                           label,       little, point("run", RegisterTable::coils, 5, PointType::boolean)};
    spec->blocks = {TableSpan{RegisterTable::holding, 0x100, 2}};
    return spec;
}

std::unique_ptr<BusDevice> device_at(std::uint8_t address) {
    DeviceOptions options;
    options.definition = thermostat();
    return make_device("thermostat", address, options);
}

}  // namespace

TEST_CASE("definition device: exactly the points' and blocks' registers answer, 02 elsewhere") {
    const auto device = device_at(7);
    CHECK(device->type() == "thermostat");
    CHECK(send(*device, adu(7, {0x04, 0x00, 0x00, 0x00, 0x05})) ==
          adu(7, {0x04, 0x0A, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}));
    CHECK(send(*device, adu(7, {0x04, 0x00, 0x00, 0x00, 0x06})) == adu(7, {0x84, 0x02}));  // input 5 is no point
    CHECK(send(*device, adu(7, {0x03, 0x00, 0x10, 0x00, 0x02})) == adu(7, {0x03, 0x04, 0, 0, 0, 0}));
    CHECK(send(*device, adu(7, {0x03, 0x00, 0x0F, 0x00, 0x02})) == adu(7, {0x83, 0x02}));
    CHECK(send(*device, adu(7, {0x03, 0x01, 0x00, 0x00, 0x02})) == adu(7, {0x03, 0x04, 0, 0, 0, 0}));  // the block
    CHECK(send(*device, adu(7, {0x03, 0x01, 0x01, 0x00, 0x02})) == adu(7, {0x83, 0x02}));
    CHECK(send(*device, adu(7, {0x01, 0x00, 0x05, 0x00, 0x01})) == adu(7, {0x01, 0x01, 0x00}));
    CHECK(send(*device, adu(7, {0x01, 0x00, 0x04, 0x00, 0x02})) == adu(7, {0x81, 0x02}));
    CHECK(send(*device, adu(7, {0x02, 0x00, 0x00, 0x00, 0x01})) == adu(7, {0x82, 0x02}));  // no discrete inputs
    CHECK(send(*device, adu(7, {0x07})) == adu(7, {0x87, 0x01}));
    CHECK(send(*device, adu(8, {0x03, 0x00, 0x10, 0x00, 0x01})) == std::nullopt);
}

TEST_CASE("definition device: writes to present coils and holding registers, read back") {
    const auto device = device_at(7);
    CHECK(send(*device, adu(7, {0x06, 0x00, 0x11, 0x00, 0xD7})) == adu(7, {0x06, 0x00, 0x11, 0x00, 0xD7}));
    CHECK(send(*device, adu(7, {0x10, 0x01, 0x00, 0x00, 0x02, 0x04, 0x12, 0x34, 0x56, 0x78})) ==
          adu(7, {0x10, 0x01, 0x00, 0x00, 0x02}));
    CHECK(send(*device, adu(7, {0x10, 0x01, 0x01, 0x00, 0x02, 0x04, 0, 1, 0, 2})) == adu(7, {0x90, 0x02}));
    CHECK(send(*device, adu(7, {0x03, 0x01, 0x00, 0x00, 0x02})) == adu(7, {0x03, 0x04, 0x12, 0x34, 0x56, 0x78}));
    CHECK(send(*device, adu(7, {0x05, 0x00, 0x05, 0xFF, 0x00})) == adu(7, {0x05, 0x00, 0x05, 0xFF, 0x00}));
    CHECK(send(*device, adu(7, {0x05, 0x00, 0x06, 0xFF, 0x00})) == adu(7, {0x85, 0x02}));
    CHECK(send(*device, adu(7, {0x0F, 0x00, 0x05, 0x00, 0x01, 0x01, 0x00})) == adu(7, {0x0F, 0x00, 0x05, 0x00, 0x01}));
    CHECK(send(*device, adu(7, {0x01, 0x00, 0x05, 0x00, 0x01})) == adu(7, {0x01, 0x01, 0x00}));
    // FC22: (0x1234 AND 0x00FF) OR (0x0F00 AND NOT 0x00FF) = 0x0F34
    CHECK(send(*device, adu(7, {0x16, 0x01, 0x00, 0x00, 0xFF, 0x0F, 0x00})) ==
          adu(7, {0x16, 0x01, 0x00, 0x00, 0xFF, 0x0F, 0x00}));
    CHECK(send(*device, adu(7, {0x03, 0x01, 0x00, 0x00, 0x01})) == adu(7, {0x03, 0x02, 0x0F, 0x34}));
    CHECK(send(*device, adu(7, {0x06, 0x00, 0x00, 0x00, 0x01})) == adu(7, {0x86, 0x02}));  // input, not holding
    CHECK(send(*device, adu(0, {0x06, 0x00, 0x10, 0x00, 0x02})) == std::nullopt);        // broadcast acts
    CHECK(send(*device, adu(7, {0x03, 0x00, 0x10, 0x00, 0x01})) == adu(7, {0x03, 0x02, 0x00, 0x02}));
}

TEST_CASE("definition device: set POINT VALUE in engineering units, set-register raw") {
    const auto device = device_at(7);
    const auto now = Clock::now();
    CHECK(device->control("set temperature 21.5", now).empty());  // 0x41AC0000, low word first
    CHECK(device->control("set runtime -2", now).empty());
    CHECK(device->control("set status 0x0001", now).empty() == false);  // numbers are decimal
    CHECK(device->control("set status 1", now).empty());
    CHECK(device->control("set sensor_fault true", now).empty());  // bit 3 of the same register
    CHECK(send(*device, adu(7, {0x04, 0x00, 0x00, 0x00, 0x05})) ==
          adu(7, {0x04, 0x0A, 0x00, 0x00, 0x41, 0xAC, 0xFF, 0xFF, 0xFF, 0xFE, 0x00, 0x09}));
    CHECK(device->control("set mode cool", now).empty());
    CHECK(device->control("set setpoint 21.5", now).empty());  // 215
    CHECK(device->control("set label AB", now).empty());
    CHECK(device->control("set little 0x01020304", now).empty() == false);
    CHECK(device->control("set little 16909060", now).empty());  // 0x01020304, bytes swapped per register
    CHECK(send(*device, adu(7, {0x03, 0x00, 0x10, 0x00, 0x02})) == adu(7, {0x03, 0x04, 0x00, 0x02, 0x00, 0xD7}));
    CHECK(send(*device, adu(7, {0x03, 0x00, 0x20, 0x00, 0x02})) == adu(7, {0x03, 0x04, 'A', 'B', 0, 0}));
    CHECK(send(*device, adu(7, {0x03, 0x00, 0x30, 0x00, 0x02})) == adu(7, {0x03, 0x04, 0x02, 0x01, 0x04, 0x03}));
    CHECK(device->control("set run on", now).empty());
    CHECK(send(*device, adu(7, {0x01, 0x00, 0x05, 0x00, 0x01})) == adu(7, {0x01, 0x01, 0x01}));

    CHECK(device->control("set-register holding 0x100 7 8", now).empty());
    CHECK(send(*device, adu(7, {0x03, 0x01, 0x00, 0x00, 0x02})) == adu(7, {0x03, 0x04, 0, 7, 0, 8}));
    CHECK(device->control("set-register coils 5 0", now).empty());
    CHECK(send(*device, adu(7, {0x01, 0x00, 0x05, 0x00, 0x01})) == adu(7, {0x01, 0x01, 0x00}));

    CHECK(device->control("set nope 1", now).find("has no point 'nope'; its points: temperature") != std::string::npos);
    CHECK(device->control("set mode warm", now).find("nor a label") != std::string::npos);
    CHECK(device->control("set setpoint 4000", now).find("outside what a int16 holds") != std::string::npos);
    CHECK(device->control("set label ABCDE", now).find("holds 4") != std::string::npos);
    CHECK(device->control("set run maybe", now).find("true or false") != std::string::npos);
    CHECK(device->control("set-register holding 0x101 1 2", now).find("has no holding") != std::string::npos);
    CHECK(device->control("set-register coils 5 2", now).find("0..1") != std::string::npos);
    CHECK(device->control("set-register tables 5 2", now).find("usage") != std::string::npos);
    CHECK(device->control("jump", now).find("unknown command 'jump'") != std::string::npos);
}

TEST_CASE("point text: every integer and float type, both word and byte orders") {
    auto p = point("p", RegisterTable::holding, 0, PointType::int64);
    CHECK(registers_of_text(p, "-1").registers == std::vector<std::uint16_t>{0xFFFF, 0xFFFF, 0xFFFF, 0xFFFF});
    p.type = PointType::uint64;
    CHECK(registers_of_text(p, "4294967296").registers == std::vector<std::uint16_t>{0, 1, 0, 0});
    p.word_order = core::WordOrder::low_first;
    CHECK(registers_of_text(p, "4294967296").registers == std::vector<std::uint16_t>{0, 0, 1, 0});
    p.type = PointType::float64;
    p.word_order = core::WordOrder::high_first;
    CHECK(registers_of_text(p, "1").registers == std::vector<std::uint16_t>{0x3FF0, 0, 0, 0});
    p.type = PointType::uint32;
    p.scale = 0.01;
    p.offset = 10;
    CHECK(registers_of_text(p, "12.5").registers == std::vector<std::uint16_t>{0, 250});
    CHECK_FALSE(registers_of_text(p, "9").error.empty());  // raw -100 for a uint32
    p.type = PointType::uint16;
    CHECK_FALSE(registers_of_text(p, "nan").error.empty());
    CHECK_FALSE(registers_of_text(p, "inf").error.empty());
}

TEST_CASE("point text: an inverted bool sets the opposite bit; a whole-register bool 1 or 0") {
    auto busy = point("busy", RegisterTable::holding, 0, PointType::boolean);
    busy.bit = 0;
    busy.invert = true;
    CHECK(registers_of_text(busy, "true", 0x0003).registers == std::vector<std::uint16_t>{0x0002});
    CHECK(registers_of_text(busy, "false", 0x0002).registers == std::vector<std::uint16_t>{0x0003});
    auto flag = point("flag", RegisterTable::holding, 1, PointType::boolean);
    CHECK(registers_of_text(flag, "true").registers == std::vector<std::uint16_t>{1});
    flag.invert = true;
    CHECK(registers_of_text(flag, "true").registers == std::vector<std::uint16_t>{0});
}

TEST_CASE("definition device: addresses outside 1-247 are refused") {
    DeviceOptions options;
    options.definition = thermostat();
    CHECK_THROWS_AS(static_cast<void>(make_device("thermostat", 0, options)), std::invalid_argument);
    CHECK_THROWS_AS(static_cast<void>(make_device("thermostat", 248, options)), std::invalid_argument);
}

}  // namespace fieldbridge::sim
