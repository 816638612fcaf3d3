// JSON payloads of the MQTT topics (docs/mqtt.md) and the state of a real profile's image.
#include <doctest/doctest.h>

#include "engine/profiles/profile_factory.hpp"
#include "northbound/mqtt/agent_source.hpp"
#include "northbound/mqtt/payloads.hpp"

namespace {

namespace fe = fieldbridge::engine;
namespace fm = fieldbridge::northbound::mqtt;
using nlohmann::json;
using namespace std::chrono_literals;

fm::ClockPair fixed_clock() {
    // 2024-05-01T12:00:00.250Z
    return fm::ClockPair{fe::TimePoint{} + 1000s, fm::WallTime{} + 1714564800s + 250ms};
}

}  // namespace

TEST_CASE("payloads: ISO 8601 UTC time with milliseconds, and epoch ms") {
    CHECK(fm::iso8601_utc(fm::WallTime{} + 1714564800s + 7ms) == "2024-05-01T12:00:00.007Z");
    CHECK(fm::iso8601_utc(fm::WallTime{}) == "1970-01-01T00:00:00.000Z");
    CHECK(fm::iso8601_utc(fm::WallTime{} - 1ms) == "1969-12-31T23:59:59.999Z");
    CHECK(fm::epoch_ms(fm::WallTime{} + 1714564800s + 7ms) == 1714564800007);
}

TEST_CASE("payloads: XEG state from its image: status word, position in mm, bits, raw registers") {
    fe::ProfileOptions options;
    auto profile = fe::make_profile(fe::DeviceType::hiwin_xeg, options);
    fe::RegisterImage image;
    const auto clock = fixed_clock();
    const std::uint16_t position_status[] = {1700, 3};
    image.update(fe::Table::input, 0x0300, position_status, clock.steady - 2s);
    const std::uint16_t dout[] = {0, 1, 0, 0, 0, 0, 0, 0};
    image.update(fe::Table::discrete_inputs, 0x0010, dout, clock.steady - 1s);

    const fm::SourceState state = fm::image_state(*profile, image, true);
    CHECK(state.online);
    CHECK(state.quality == fe::Quality::good);
    REQUIRE(state.updated);
    CHECK(*state.updated == clock.steady - 1s);

    const json j = fm::state_payload("gripper1", "hiwin-xeg", state, clock);
    CHECK(j["device"] == "gripper1");
    CHECK(j["type"] == "hiwin-xeg");
    CHECK(j["online"] == true);
    CHECK(j["quality"] == "good");
    // The time of the newest value (the discrete inputs, 1 s before the clock).
    CHECK(j["time"] == "2024-05-01T11:59:59.250Z");
    CHECK(j["time_ms"] == 1714564799250);
    CHECK(j["fields"]["status"] == "holding");
    CHECK(j["fields"]["position_mm"] == doctest::Approx(17.0));
    CHECK(j["fields"]["do_hold"] == true);
    CHECK(j["units"]["position_mm"] == "mm");
    CHECK(j["raw"]["input"]["0x0300"] == 1700);
    CHECK(j["raw"]["input"]["0x0301"] == 3);
    CHECK(j["raw"]["discrete_inputs"]["0x0011"] == 1);
}

TEST_CASE("payloads: quality is offline while offline, stale when any value is stale, unknown before any read") {
    auto profile = fe::make_profile(fe::DeviceType::excd203mb, fe::ProfileOptions{});
    fe::RegisterImage image;
    CHECK(fm::image_state(*profile, image, true).quality == fe::Quality::unknown);
    const std::uint16_t values[] = {0, 0, 5, 0, 0, 1};
    image.update(fe::Table::holding, 0x0200, values, fe::Clock::now());
    CHECK(fm::image_state(*profile, image, true).quality == fe::Quality::good);
    image.mark_stale(fe::Table::holding, 0x0200, 1);
    CHECK(fm::image_state(*profile, image, true).quality == fe::Quality::stale);
    image.set_offline(true);
    const auto offline = fm::image_state(*profile, image, true);
    CHECK(offline.quality == fe::Quality::offline);
    CHECK_FALSE(offline.online);
    CHECK(fm::image_state(*profile, image, false).quality == fe::Quality::offline);
}

TEST_CASE("payloads: alarm event, active set and command result") {
    const auto clock = fixed_clock();
    const fe::Alarm alarm{"move_alarm", "move alarm", fe::Severity::error, "input 0x0301"};
    const json raised = fm::alarm_event_payload("g1", fm::AlarmEvent{fm::AlarmTransition::raised, alarm, clock.steady}, clock);
    CHECK(raised["event"] == "raised");
    CHECK(raised["code"] == "move_alarm");
    CHECK(raised["severity"] == "error");
    CHECK(raised["source"] == "input 0x0301");
    CHECK(raised["time"] == "2024-05-01T12:00:00.250Z");
    const json cleared = fm::alarm_event_payload("g1", fm::AlarmEvent{fm::AlarmTransition::cleared, alarm, clock.steady}, clock);
    CHECK(cleared["event"] == "cleared");

    const json set = fm::alarm_set_payload("g1", {fm::ActiveAlarm{alarm, clock.steady - 3s}}, clock);
    CHECK(set["event"] == "active");
    REQUIRE(set["alarms"].size() == 1);
    CHECK(set["alarms"][0]["code"] == "move_alarm");
    CHECK(set["alarms"][0]["since"] == "2024-05-01T11:59:57.250Z");
    CHECK(fm::alarm_set_payload("g1", {}, clock)["alarms"].empty());

    const json ok = fm::command_result_payload("g1", json("c-1"), "move", fm::CommandOutcome{}, clock);
    CHECK(ok["id"] == "c-1");
    CHECK(ok["ok"] == true);
    CHECK_FALSE(ok.contains("error"));
    fm::CommandOutcome failed{false, "rejected", "out of range", fieldbridge::protocol::ExceptionCode::illegal_data_value,
                               {}};
    const json bad = fm::command_result_payload("g1", json(7), "move", failed, clock);
    CHECK(bad["id"] == 7);
    CHECK(bad["ok"] == false);
    CHECK(bad["error"] == "rejected");
    CHECK(bad["exception"] == 3);
}

TEST_CASE("payloads: a read's result carries the points' values, an enum with its code") {
    const fm::ClockPair clock = fixed_clock();
    fm::SourceState state;
    state.decoded.fields = {fieldbridge::engine::Field{"temperature", 20.25, "°C"},
                            fieldbridge::engine::Field{"mode", std::string{"heat"}, ""},
                            fieldbridge::engine::Field{"mode_code", std::int64_t{1}, ""}};
    const json values = fm::point_values(state, {"mode", "temperature", "setpoint"});
    CHECK(values == json::parse(R"({"mode":"heat","mode_code":1,"temperature":20.25,"setpoint":null})"));
    fm::CommandOutcome read;
    read.values = values;
    const json result = fm::command_result_payload("t1", json(8), "read", read, clock);
    CHECK(result["ok"] == true);
    CHECK(result["values"]["mode"] == "heat");
    // Other results have no `values`.
    CHECK_FALSE(fm::command_result_payload("t1", json(9), "stop", fm::CommandOutcome{}, clock).contains("values"));
}
