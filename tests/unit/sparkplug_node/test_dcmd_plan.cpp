// DCMD -> MQTT commands (northbound/sparkplug_node/dcmd_plan.*): writable points as one
// `write`, built-in writable fields as the op that sets them, `Commands/<op>` with its
// parameters; every refusal names the metric and plans nothing.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "engine/profiles/wtec_common.hpp"
#include "engine/profiles/xeg_profile.hpp"
#include "northbound/sparkplug_node/dcmd_plan.hpp"
#include "point_builders.hpp"

namespace {

namespace fe = fieldbridge::engine;
namespace sp = fieldbridge::northbound::sparkplug;
namespace sn = fieldbridge::northbound::sparkplug_node;
namespace core = fieldbridge::core;
using nlohmann::json;
using fieldbridge::test::point_def;
using T = sp::DataType;

struct PlanRig {
    core::PointModel points;
    sp::MetricCatalogue catalogue;
    PlanRig() {
        points.points.push_back(point_def("setpoint", core::RegisterTable::holding, 10, core::PointType::float32, true));
        points.points.push_back(point_def("offset", core::RegisterTable::holding, 12, core::PointType::int16, true));
        points.points.push_back(point_def("temperature", core::RegisterTable::input, 0, core::PointType::float32));
        sp::DeviceShape thermostat;
        thermostat.name = "tc1";
        thermostat.points = &points;
        catalogue.add_device(thermostat);

        sp::DeviceShape gripper;
        gripper.name = "wtec";
        gripper.state.fields = {fe::Field{"position_pct", std::int64_t{10}, "%"},
                                fe::Field{"force_pct", std::int64_t{50}, "%"}};
        gripper.writable_fields = {"force_pct"};
        gripper.operations = fe::wtec_operations();
        catalogue.add_device(gripper);

        sp::DeviceShape xeg;
        xeg.name = "xeg";
        xeg.state.fields = {fe::Field{"position_mm", 1.0, "mm"}};
        xeg.operations = fe::xeg_operations();
        catalogue.add_device(xeg);
    }
};

sp::CommandMetric by_name(std::string name, sp::Value value, std::optional<T> type = std::nullopt) {
    return sp::CommandMetric{sp::MetricReference{std::move(name), std::nullopt}, type, std::move(value)};
}

sp::Command command(std::vector<sp::CommandMetric> metrics) { return sp::Command{std::nullopt, std::move(metrics)}; }

sn::DcmdPlan plan(const PlanRig& rig, std::string_view device, std::vector<sp::CommandMetric> metrics,
                  const sn::StoredArguments& stored = {}) {
    const fe::OperationSet ops = device == "wtec" ? fe::wtec_operations() : fe::OperationSet{};
    return sn::plan_dcmd(rig.catalogue, device, command(std::move(metrics)), stored, fe::field_setters(ops));
}

}  // namespace

TEST_CASE("writable points of one DCMD make one write command with every value") {
    const PlanRig rig;
    const auto p = plan(rig, "tc1", {by_name("setpoint", 21.5F, T::float32), by_name("offset", std::uint64_t{0xFFFFFFFFu})});
    REQUIRE(p.ok());
    REQUIRE(p.commands.size() == 1);
    CHECK(p.commands[0]["op"] == "write");
    CHECK(p.commands[0]["values"]["setpoint"].get<double>() == doctest::Approx(21.5));
    // An Int16 sent in an int_value without a datatype: the low 32 bits, -1.
    CHECK(p.commands[0]["values"]["offset"] == -1);
}

TEST_CASE("a metric by alias is the same metric") {
    const PlanRig rig;
    const sp::CatalogueMetric* setpoint = rig.catalogue.find("tc1", sp::MetricReference{"setpoint", std::nullopt});
    REQUIRE(setpoint != nullptr);
    const auto p = plan(rig, "tc1", {sp::CommandMetric{sp::MetricReference{std::nullopt, setpoint->alias}, std::nullopt, 20.0F}});
    REQUIRE(p.ok());
    CHECK(p.commands[0]["values"]["setpoint"].get<double>() == doctest::Approx(20.0));
}

TEST_CASE("one bad metric refuses the whole DCMD, naming it") {
    const PlanRig rig;
    SUBCASE("unknown name") {
        const auto p = plan(rig, "tc1", {by_name("setpoint", 20.0F), by_name("nope", 1.0)});
        CHECK_FALSE(p.ok());
        CHECK(p.error.find("\"nope\"") != std::string::npos);
        CHECK(p.commands.empty());
    }
    SUBCASE("unknown alias") {
        const auto p = plan(rig, "tc1", {sp::CommandMetric{sp::MetricReference{std::nullopt, 999}, std::nullopt, 1.0F}});
        CHECK_FALSE(p.ok());
        CHECK(p.error.find("alias 999") != std::string::npos);
    }
    SUBCASE("read-only point") {
        const auto p = plan(rig, "tc1", {by_name("setpoint", 20.0F), by_name("temperature", 1.0F)});
        CHECK_FALSE(p.ok());
        CHECK(p.error.find("read-only") != std::string::npos);
        CHECK(p.commands.empty());
    }
    SUBCASE("wrong datatype given") {
        const auto p = plan(rig, "tc1", {by_name("setpoint", 20.0, T::float64)});
        CHECK_FALSE(p.ok());
        CHECK(p.error.find("Float") != std::string::npos);
    }
    SUBCASE("wrong value type") {
        const auto p = plan(rig, "tc1", {by_name("setpoint", std::string("warm"))});
        CHECK_FALSE(p.ok());
    }
    SUBCASE("NaN and infinity") {
        CHECK_FALSE(plan(rig, "tc1", {by_name("setpoint", std::numeric_limits<float>::quiet_NaN())}).ok());
        CHECK_FALSE(plan(rig, "tc1", {by_name("setpoint", std::numeric_limits<float>::infinity())}).ok());
    }
    SUBCASE("an Int16 out of its range") {
        const auto p = plan(rig, "tc1", {by_name("offset", std::uint64_t{40000})});
        CHECK_FALSE(p.ok());
        CHECK(p.error.find("does not fit") != std::string::npos);
    }
    SUBCASE("a read-only built-in field") {
        const auto p = plan(rig, "wtec", {by_name("position_pct", std::uint64_t{20})});
        CHECK_FALSE(p.ok());
        CHECK(p.error.find("read-only") != std::string::npos);
    }
}

TEST_CASE("a built-in writable field is the op that sets it") {
    const PlanRig rig;
    const auto p = plan(rig, "wtec", {by_name("force_pct", std::uint64_t{40}, T::int64)});
    REQUIRE(p.ok());
    REQUIRE(p.commands.size() == 1);
    CHECK(p.commands[0]["op"] == "force");
    CHECK(p.commands[0]["percent"] == 40);
}

TEST_CASE("Commands/<op> metrics: born writable, typed by the op's fields") {
    const PlanRig rig;
    const auto* move = rig.catalogue.find("xeg", sp::MetricReference{"Commands/move", std::nullopt});
    REQUIRE(move != nullptr);
    CHECK(move->datatype == T::boolean);
    CHECK(move->writable);
    const auto* position = rig.catalogue.find("xeg", sp::MetricReference{"Commands/move/position_mm", std::nullopt});
    REQUIRE(position != nullptr);
    CHECK(position->datatype == T::float64);
    CHECK(position->op == "move");
    CHECK(position->argument == "position_mm");
    const auto* grip = rig.catalogue.find("wtec", sp::MetricReference{"Commands/grip/force_pct", std::nullopt});
    REQUIRE(grip != nullptr);
    CHECK(grip->datatype == T::int64);
}

TEST_CASE("Commands/<op> = true runs the op with this DCMD's parameters, then the stored ones") {
    const PlanRig rig;
    SUBCASE("all in one DCMD") {
        const auto p = plan(rig, "xeg", {by_name("Commands/move/position_mm", 10.0), by_name("Commands/move/speed_mm_s", 20.0),
                                         by_name("Commands/move", true)});
        REQUIRE(p.ok());
        REQUIRE(p.commands.size() == 1);
        CHECK(p.commands[0] == json{{"id", "sparkplug-dcmd"}, {"op", "move"}, {"position_mm", 10.0}, {"speed_mm_s", 20.0}});
        CHECK(p.arguments.size() == 2);
    }
    SUBCASE("stored parameters fill in, the DCMD's win") {
        const sn::StoredArguments stored{{"Commands/move/position_mm", 5.0}, {"Commands/move/speed_mm_s", 7.0}};
        const auto p = plan(rig, "xeg", {by_name("Commands/move/position_mm", 12.0), by_name("Commands/move", true)}, stored);
        REQUIRE(p.ok());
        CHECK(p.commands[0]["position_mm"] == 12.0);
        CHECK(p.commands[0]["speed_mm_s"] == 7.0);
    }
    SUBCASE("a parameter alone is only stored") {
        const auto p = plan(rig, "xeg", {by_name("Commands/move/position_mm", 12.0)});
        REQUIRE(p.ok());
        CHECK(p.commands.empty());
        REQUIRE(p.arguments.size() == 1);
        CHECK(p.arguments[0].first->name == "Commands/move/position_mm");
    }
    SUBCASE("false runs nothing") {
        const auto p = plan(rig, "xeg", {by_name("Commands/move", false)});
        REQUIRE(p.ok());
        CHECK(p.commands.empty());
    }
    SUBCASE("a missing parameter is left to the command parser") {
        const auto p = plan(rig, "xeg", {by_name("Commands/move", true)});
        REQUIRE(p.ok());
        CHECK(p.commands[0] == json{{"id", "sparkplug-dcmd"}, {"op", "move"}});
    }
}

TEST_CASE("json_value reads each datatype's range") {
    CHECK(sn::json_value(T::int8, std::uint64_t{0xFFFFFF80u}).value == -128);
    CHECK_FALSE(sn::json_value(T::int8, std::uint64_t{128}).error.empty());
    CHECK(sn::json_value(T::int64, std::uint64_t{0xFFFFFFFFFFFFFFFFull}).value == -1);
    CHECK(sn::json_value(T::uint16, std::uint64_t{65535}).value == 65535);
    CHECK_FALSE(sn::json_value(T::uint16, std::uint64_t{65536}).error.empty());
    CHECK(sn::json_value(T::uint64, std::uint64_t{0xFFFFFFFFFFFFFFFFull}).value == 0xFFFFFFFFFFFFFFFFull);
    CHECK(sn::json_value(T::boolean, true).value == true);
    CHECK_FALSE(sn::json_value(T::boolean, std::uint64_t{1}).error.empty());
    CHECK(sn::json_value(T::string, std::string("heat")).value == "heat");
    CHECK_FALSE(sn::json_value(T::datetime, std::uint64_t{1}).error.empty());
}
