// The point ops `write` and `read` of a device with points (docs/mqtt.md, "Devices with
// points"): JSON values -> the codec's write requests, all or nothing; read requests.
#include <doctest/doctest.h>

#include "core/point.hpp"
#include "northbound/mqtt/command_parser.hpp"
#include "northbound/mqtt/point_commands.hpp"
#include "point_builders.hpp"

namespace {

namespace core = fieldbridge::core;
namespace fe = fieldbridge::engine;
namespace fm = fieldbridge::northbound::mqtt;
namespace fp = fieldbridge::protocol;

using fieldbridge::test::point_def;

/// A thermostat: float32 temperature (read-only), float32 setpoint 5..35 (writable),
/// uint16 mode enum off/heat/cool (writable), a coil `enabled` (writable), a string name.
core::PointModel thermostat() {
    core::PointModel model;
    model.points.push_back(point_def("temperature", core::RegisterTable::input, 0x0000, core::PointType::float32));
    auto setpoint = point_def("setpoint", core::RegisterTable::holding, 0x0010, core::PointType::float32);
    setpoint.writable = true;
    setpoint.min = 5.0;
    setpoint.max = 35.0;
    setpoint.unit = "°C";
    model.points.push_back(setpoint);
    auto mode = point_def("mode", core::RegisterTable::holding, 0x0012, core::PointType::uint16);
    mode.writable = true;
    mode.labels = {{0, "off"}, {1, "heat"}, {2, "cool"}};
    model.points.push_back(mode);
    auto enabled = point_def("enabled", core::RegisterTable::coils, 0x0003, core::PointType::boolean);
    enabled.writable = true;
    model.points.push_back(enabled);
    auto label = point_def("label", core::RegisterTable::holding, 0x0020, core::PointType::string);
    label.count = 4;
    model.points.push_back(label);
    return model;
}

fm::ParseResult parse(const std::string& payload, const core::PointModel& model) {
    return fm::parse_command(payload, fe::OperationSet{}, {}, &model);
}

fm::CommandError refused(const std::string& payload, const core::PointModel& model) {
    const auto result = parse(payload, model);
    REQUIRE(std::holds_alternative<fm::CommandError>(result));
    return std::get<fm::CommandError>(result);
}

}  // namespace

TEST_CASE("write: values in engineering units become the points' registers, in the points' order") {
    const auto model = thermostat();
    // The JSON names mode first; the setpoint comes first among the device's points.
    const auto result = parse(R"({"id":1,"op":"write","values":{"mode":"heat","setpoint":21.5,"enabled":true}})", model);
    REQUIRE(std::holds_alternative<fm::ParsedCommand>(result));
    const auto& command = std::get<fm::ParsedCommand>(result);
    CHECK(command.op == "write");
    CHECK(command.requests == std::vector<fp::Request>{fp::WriteMultipleRegistersRequest{0x0010, {0x41AC, 0x0000}},
                                                       fp::WriteSingleRegisterRequest{0x0012, 1},
                                                       fp::WriteSingleCoilRequest{0x0003, true}});
    // An enum point also takes its code.
    const auto by_code = parse(R"({"id":2,"op":"write","values":{"mode":2}})", model);
    REQUIRE(std::holds_alternative<fm::ParsedCommand>(by_code));
    CHECK(std::get<fm::ParsedCommand>(by_code).requests ==
          std::vector<fp::Request>{fp::WriteSingleRegisterRequest{0x0012, 2}});
}

TEST_CASE("write is all or nothing: the first refusal names the point and nothing is sent") {
    const auto model = thermostat();
    const auto unknown = refused(R"({"id":1,"op":"write","values":{"setpoint":20,"fan":1}})", model);
    CHECK(unknown.kind == fm::CommandErrorKind::invalid_field);
    CHECK(unknown.message.find("\"fan\"") != std::string::npos);
    const auto read_only = refused(R"({"id":1,"op":"write","values":{"temperature":20}})", model);
    CHECK(read_only.kind == fm::CommandErrorKind::invalid_field);
    CHECK(read_only.message.find("read-only") != std::string::npos);
    const auto wrong_type = refused(R"({"id":1,"op":"write","values":{"setpoint":"warm"}})", model);
    CHECK(wrong_type.kind == fm::CommandErrorKind::invalid_field);
    CHECK(refused(R"({"id":1,"op":"write","values":{"enabled":1}})", model).kind ==
          fm::CommandErrorKind::invalid_field);
    const auto too_high = refused(R"({"id":1,"op":"write","values":{"mode":"heat","setpoint":35.5}})", model);
    CHECK(too_high.kind == fm::CommandErrorKind::out_of_range);
    CHECK(too_high.message.find("\"setpoint\"") != std::string::npos);
    CHECK(refused(R"({"id":1,"op":"write","values":{"mode":"auto"}})", model).kind ==
          fm::CommandErrorKind::out_of_range);
    CHECK(refused(R"({"id":1,"op":"write"})", model).kind == fm::CommandErrorKind::missing_field);
    CHECK(refused(R"({"id":1,"op":"write","values":[]})", model).kind == fm::CommandErrorKind::invalid_field);
    CHECK(refused(R"({"id":1,"op":"write","values":{"setpoint":20},"extra":1})", model).kind ==
          fm::CommandErrorKind::invalid_field);
}

TEST_CASE("read: the reads covering the named points, and the names the result answers with") {
    const auto model = thermostat();
    const auto result = parse(R"({"id":"r","op":"read","points":["mode","setpoint","mode"]})", model);
    REQUIRE(std::holds_alternative<fm::ParsedCommand>(result));
    const auto& command = std::get<fm::ParsedCommand>(result);
    CHECK(command.read_points == std::vector<std::string>{"mode", "setpoint"});
    // setpoint (0x0010-0x0011) and mode (0x0012) are adjacent: one read.
    CHECK(command.requests == std::vector<fp::Request>{fp::ReadRegistersRequest{0x03, 0x0010, 3}});
    CHECK(refused(R"({"id":1,"op":"read","points":["nope"]})", model).kind == fm::CommandErrorKind::invalid_field);
    CHECK(refused(R"({"id":1,"op":"read","points":[1]})", model).kind == fm::CommandErrorKind::invalid_field);
    CHECK(refused(R"({"id":1,"op":"read"})", model).kind == fm::CommandErrorKind::missing_field);
}

TEST_CASE("the point ops exist only where they apply, and unknown_op lists them") {
    auto read_only = thermostat();
    for (auto& p : read_only.points) p.writable = false;
    const auto no_write = refused(R"({"id":1,"op":"write","values":{"setpoint":20}})", read_only);
    CHECK(no_write.kind == fm::CommandErrorKind::unknown_op);
    CHECK(no_write.message.find("read") != std::string::npos);
    // A device without points: neither op.
    const auto none = fm::parse_command(R"({"id":1,"op":"read","points":["x"]})", fe::OperationSet{}, {}, nullptr);
    REQUIRE(std::holds_alternative<fm::CommandError>(none));
    CHECK(std::get<fm::CommandError>(none).kind == fm::CommandErrorKind::unknown_op);
    CHECK(fm::command_ops(fe::OperationSet{}, nullptr) == std::vector<std::string_view>{"set_register", "write_registers"});
    const auto model = thermostat();
    CHECK(fm::command_ops(fe::OperationSet{}, &model) ==
          std::vector<std::string_view>{"write", "read", "set_register", "write_registers"});
}
