// The R6's MQTT operations (northbound/upstream/r6_operations.hpp) against seed 004:
// the fields of each op, and the PDUs of the manual's example frames (3.2.1, 3.2.2,
// 3.3.3) and address table (section 4).
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "northbound/upstream/r6_operations.hpp"

namespace {

namespace fe = fieldbridge::engine;
namespace fp = fieldbridge::protocol;
using fieldbridge::northbound::r6::r6_operations;

/// The PDUs @p op sends with @p values (fails the test when it refuses).
std::vector<fp::Bytes> pdus(std::string_view op,
                            std::initializer_list<std::pair<std::string_view, fe::ArgumentValue>> values = {}) {
    const fe::Operation* operation = r6_operations().find(op);
    REQUIRE_MESSAGE(operation != nullptr, "no op " << op);
    fe::OperationArgs args;
    for (const auto& [name, value] : values) args.set(name, value);
    const fe::OperationWrites writes = operation->writes(args, {});
    REQUIRE(std::holds_alternative<std::vector<fp::Request>>(writes));
    std::vector<fp::Bytes> out;
    for (const fp::Request& r : std::get<std::vector<fp::Request>>(writes)) out.push_back(fp::encode_request(r));
    return out;
}

using Pdus = std::vector<fp::Bytes>;

}  // namespace

TEST_CASE("r6 operations: names and fields (docs/mqtt.md, \"Huacheng R6\")") {
    const fe::OperationSet set = r6_operations();
    CHECK(set.name == "r6");
    std::vector<std::string_view> names;
    for (const fe::Operation& op : set.operations) names.push_back(op.name);
    CHECK(names == std::vector<std::string_view>{"stop", "pause", "start", "clear_alarm", "global_speed", "output"});
    const auto* clear = set.find("clear_alarm");
    REQUIRE(clear != nullptr);
    REQUIRE(clear->fields.size() == 1);
    CHECK(clear->fields[0].name == "resume");
    CHECK_FALSE(clear->fields[0].optional);  // both resume motion: no default
    CHECK(std::get<fe::ChoiceField>(clear->fields[0].type).options == std::vector<std::string_view>{"next", "continue"});
    const auto* speed = set.find("global_speed");
    REQUIRE(speed != nullptr);
    REQUIRE(speed->fields.size() == 1);
    CHECK(std::get<fe::NumberField>(speed->fields[0].type).min == 0.0);
    CHECK(std::get<fe::NumberField>(speed->fields[0].type).max == 100.0);
    const auto* output = set.find("output");
    REQUIRE(output != nullptr);
    REQUIRE(output->fields.size() == 3);
    CHECK(output->fields[0].name == "board");
    CHECK(std::get<fe::IntegerField>(output->fields[0].type).max == 7);
    CHECK(output->fields[1].name == "point");
    CHECK(std::get<fe::IntegerField>(output->fields[1].type).max == 31);
    CHECK(output->fields[2].name == "on");
    CHECK(std::holds_alternative<fe::BooleanField>(output->fields[2].type));
}

TEST_CASE("r6 operations: the manual's frames (seed 004 3.2.1, 3.2.2, 3.3.3, section 4)") {
    // 3.2.1 example "01 06 4e 20 00 01": stop the current action.
    CHECK(pdus("stop") == Pdus{{0x06, 0x4E, 0x20, 0x00, 0x01}});
    // Section 4: 20001 (0x4E21) pause, 20003 (0x4E23) start button; FC06, any value.
    CHECK(pdus("pause") == Pdus{{0x06, 0x4E, 0x21, 0x00, 0x01}});
    CHECK(pdus("start") == Pdus{{0x06, 0x4E, 0x23, 0x00, 0x01}});
    // Section 4: 20005 (0x4E25) clear the alarm and run the next instruction, 20006
    // (0x4E26) clear it and continue the automatic run.
    CHECK(pdus("clear_alarm", {{"resume", std::string("next")}}) == Pdus{{0x06, 0x4E, 0x25, 0x00, 0x01}});
    CHECK(pdus("clear_alarm", {{"resume", std::string("continue")}}) == Pdus{{0x06, 0x4E, 0x26, 0x00, 0x01}});
    // 3.2.2 example "01 06 4e e8 00 64": global speed 10.0 %; 0.1 % resolution, rounded.
    CHECK(pdus("global_speed", {{"percent", 10.0}}) == Pdus{{0x06, 0x4E, 0xE8, 0x00, 0x64}});
    CHECK(pdus("global_speed", {{"percent", 12.35}}) == Pdus{{0x06, 0x4E, 0xE8, 0x00, 0x7C}});
    CHECK(pdus("global_speed", {{"percent", 100.0}}) == Pdus{{0x06, 0x4E, 0xE8, 0x03, 0xE8}});
    // 3.3.3 example "01 10 4e 58 00 03 06 00 00 00 01 00 01": board 0, point 1, on.
    CHECK(pdus("output", {{"board", std::int64_t{0}}, {"point", std::int64_t{1}}, {"on", true}}) ==
          Pdus{{0x10, 0x4E, 0x58, 0x00, 0x03, 0x06, 0x00, 0x00, 0x00, 0x01, 0x00, 0x01}});
    CHECK(pdus("output", {{"board", std::int64_t{7}}, {"point", std::int64_t{31}}, {"on", false}}) ==
          Pdus{{0x10, 0x4E, 0x58, 0x00, 0x03, 0x06, 0x00, 0x07, 0x00, 0x1F, 0x00, 0x00}});
}
