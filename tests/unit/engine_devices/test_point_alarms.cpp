// Alarm rules on points: conditions, hysteresis, texts.
#include <doctest/doctest.h>

#include <vector>

#include "engine/points/point_alarms.hpp"

namespace {

namespace fc = fieldbridge::core;
namespace pts = fieldbridge::engine::points;
using Regs = std::vector<std::uint16_t>;

fc::AlarmRule rule(fc::AlarmCondition condition, double threshold, double hysteresis = 0) {
    fc::AlarmRule r;
    r.name = "r";
    r.point = "p";
    r.condition = condition;
    r.threshold = threshold;
    r.hysteresis = hysteresis;
    return r;
}

fc::PointDef int_point(fc::PointType type = fc::PointType::int16) {
    fc::PointDef p;
    p.name = "level";
    p.type = type;
    return p;
}

}  // namespace

TEST_CASE("point alarms: above and below with hysteresis") {
    const fc::PointDef p = int_point();
    const fc::AlarmRule above = rule(fc::AlarmCondition::above, 100, 5);
    CHECK_FALSE(pts::alarm_raised(above, p, Regs{100}, false));
    CHECK(pts::alarm_raised(above, p, Regs{101}, false));
    CHECK(pts::alarm_raised(above, p, Regs{96}, true));   // inside the band: stays
    CHECK_FALSE(pts::alarm_raised(above, p, Regs{95}, true));  // back past 100 - 5
    CHECK_FALSE(pts::alarm_raised(above, p, Regs{96}, false));
    const fc::AlarmRule below = rule(fc::AlarmCondition::below, -10, 2);
    CHECK(pts::alarm_raised(below, p, Regs{0xFFF5}, false));  // -11
    CHECK(pts::alarm_raised(below, p, Regs{0xFFF7}, true));   // -9
    CHECK_FALSE(pts::alarm_raised(below, p, Regs{0xFFF8}, true));  // -8
    // Scaled: compared in engineering units.
    fc::PointDef scaled = int_point();
    scaled.scale = 0.1;
    CHECK(pts::alarm_raised(rule(fc::AlarmCondition::above, 10), scaled, Regs{101}, false));
    CHECK_FALSE(pts::alarm_raised(rule(fc::AlarmCondition::above, 10), scaled, Regs{100}, false));
}

TEST_CASE("point alarms: equals, not_equals, bit; what cannot be compared raises nothing") {
    fc::PointDef mode = int_point(fc::PointType::uint16);
    mode.labels = {{0, "off"}, {3, "fault"}};
    CHECK(pts::alarm_raised(rule(fc::AlarmCondition::equals, 3), mode, Regs{3}, false));
    CHECK_FALSE(pts::alarm_raised(rule(fc::AlarmCondition::equals, 3), mode, Regs{2}, true));
    CHECK(pts::alarm_raised(rule(fc::AlarmCondition::not_equals, 0), mode, Regs{2}, false));
    CHECK_FALSE(pts::alarm_raised(rule(fc::AlarmCondition::not_equals, 0), mode, Regs{0}, false));
    fc::AlarmRule bit = rule(fc::AlarmCondition::bit, 0);
    bit.bit = 17;
    const fc::PointDef wide = int_point(fc::PointType::uint32);
    CHECK(pts::alarm_raised(bit, wide, Regs{0x0002, 0x0000}, false));
    CHECK_FALSE(pts::alarm_raised(bit, wide, Regs{0x0001, 0xFFFF}, false));
    fc::PointDef flag = int_point(fc::PointType::boolean);
    flag.table = fc::RegisterTable::discrete_inputs;
    CHECK(pts::alarm_raised(rule(fc::AlarmCondition::equals, 1), flag, Regs{1}, false));
    fc::PointDef text = int_point(fc::PointType::string);
    text.count = 1;
    CHECK_FALSE(pts::alarm_raised(rule(fc::AlarmCondition::not_equals, 0), text, Regs{0x4142}, false));
    const fc::PointDef f = int_point(fc::PointType::float32);
    CHECK_FALSE(pts::alarm_raised(rule(fc::AlarmCondition::not_equals, 0), f, Regs{0x7FC0, 0}, false));  // NaN
    CHECK_FALSE(pts::alarm_raised(bit, f, Regs{0x41AC, 0}, false));
}

TEST_CASE("point alarms: texts") {
    fc::PointDef p = int_point();
    p.unit = "bar";
    CHECK(pts::alarm_text(rule(fc::AlarmCondition::above, 2.5), p, Regs{30}) == "level above 2.5 bar");
    CHECK(pts::alarm_text(rule(fc::AlarmCondition::below, 1), p, Regs{0}) == "level below 1 bar");
    fc::PointDef mode = int_point(fc::PointType::uint16);
    mode.name = "mode";
    mode.labels = {{3, "fault"}};
    CHECK(pts::alarm_text(rule(fc::AlarmCondition::equals, 3), mode, Regs{3}) == "mode is fault");
    CHECK(pts::alarm_text(rule(fc::AlarmCondition::not_equals, 4), mode, Regs{3}) == "mode is not 4");
    fc::AlarmRule bit = rule(fc::AlarmCondition::bit, 0);
    bit.bit = 3;
    CHECK(pts::alarm_text(bit, mode, Regs{8}) == "bit 3 of mode set");
    bit.text = "Door open";
    CHECK(pts::alarm_text(bit, mode, Regs{8}) == "Door open");
}

TEST_CASE("point alarms: {value} in a text is the value as the state shows it; source names the point by default") {
    fc::PointDef code = int_point(fc::PointType::uint16);
    code.name = "alarm_code";
    fc::AlarmRule r = rule(fc::AlarmCondition::not_equals, 0);
    r.text = "alarm code {value} (ralarm); clear it";
    CHECK(pts::alarm_text(r, code, Regs{321}) == "alarm code 321 (ralarm); clear it");
    r.text = "{value}{value}, {value}";
    CHECK(pts::alarm_text(r, code, Regs{7}) == "77, 7");
    // An enum: its label (the code when it has none); a scaled value as a number; a
    // text without quotes.
    fc::PointDef mode = int_point(fc::PointType::uint16);
    mode.labels = {{3, "fault"}};
    r.text = "mode {value}";
    CHECK(pts::alarm_text(r, mode, Regs{3}) == "mode fault");
    CHECK(pts::alarm_text(r, mode, Regs{9}) == "mode 9");
    fc::PointDef scaled = int_point();
    scaled.scale = 0.1;
    CHECK(pts::alarm_text(r, scaled, Regs{215}) == "mode 21.5");
    fc::PointDef version = int_point(fc::PointType::uint32);
    version.format = fc::PointFormat::hex;
    CHECK(pts::alarm_text(r, version, Regs{0x0000, 0x0078}) == "mode 0x00000078");

    CHECK(pts::alarm_source(r) == "point p");
    r.source = "holding 0x02D6";
    CHECK(pts::alarm_source(r) == "holding 0x02D6");
}

TEST_CASE("point alarms: a format: hex point compares as the integer it is; an inverted bool as it reads") {
    fc::PointDef version = int_point(fc::PointType::uint32);
    version.format = fc::PointFormat::hex;
    CHECK(pts::alarm_raised(rule(fc::AlarmCondition::above, 0x77), version, Regs{0x0000, 0x0078}, false));
    CHECK_FALSE(pts::alarm_raised(rule(fc::AlarmCondition::above, 0x78), version, Regs{0x0000, 0x0078}, false));
    fc::AlarmRule bit = rule(fc::AlarmCondition::bit, 0);
    bit.bit = 16;
    CHECK(pts::alarm_raised(bit, version, Regs{0x0001, 0x0000}, false));
    fc::PointDef busy = int_point(fc::PointType::boolean);
    busy.bit = 0;
    busy.invert = true;
    CHECK(pts::alarm_raised(rule(fc::AlarmCondition::equals, 1), busy, Regs{0}, false));
    CHECK_FALSE(pts::alarm_raised(rule(fc::AlarmCondition::equals, 1), busy, Regs{1}, false));
}
