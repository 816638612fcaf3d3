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
    CHECK(pts::alarm_text(rule(fc::AlarmCondition::above, 2.5), p) == "level above 2.5 bar");
    CHECK(pts::alarm_text(rule(fc::AlarmCondition::below, 1), p) == "level below 1 bar");
    fc::PointDef mode = int_point(fc::PointType::uint16);
    mode.name = "mode";
    mode.labels = {{3, "fault"}};
    CHECK(pts::alarm_text(rule(fc::AlarmCondition::equals, 3), mode) == "mode is fault");
    CHECK(pts::alarm_text(rule(fc::AlarmCondition::not_equals, 4), mode) == "mode is not 4");
    fc::AlarmRule bit = rule(fc::AlarmCondition::bit, 0);
    bit.bit = 3;
    CHECK(pts::alarm_text(bit, mode) == "bit 3 of mode set");
    bit.text = "Door open";
    CHECK(pts::alarm_text(bit, mode) == "Door open");
}
