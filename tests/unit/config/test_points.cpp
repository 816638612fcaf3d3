// Points and alarms inline under a device (docs/devices.md): each rule of a point,
// names, overlaps, alarms, and the defaults the built model carries.

#include <doctest/doctest.h>

#include <chrono>
#include <string>

#include "config_test_support.hpp"

using namespace fieldbridge::config;
using namespace fieldbridge::config::test;
using fieldbridge::core::AlarmCondition;
using fieldbridge::core::AlarmSeverity;
using fieldbridge::core::ByteOrder;
using fieldbridge::core::PointType;
using namespace std::chrono_literals;

namespace {

/// One generic device; @p extra is appended to it from line 10 on (at the device's
/// indentation: "        points:" ...).
std::string device_with(std::string_view extra, std::string_view type = "modbus") {
    return one_device_config(type, extra);
}

/// device_with() with one point `p` whose keys are @p keys (line 11, keys from column 13).
std::string one_point(std::string_view keys) {
    return device_with("        points:\n          - {name: p, " + std::string(keys) + "}\n");
}

const DeviceConfig& only_device(const Config& config) { return config.lines.at(0).devices.at(0); }

}  // namespace

TEST_CASE("inline points build with every default applied") {
    const auto config = load_ok(device_with(R"(        word_order: low_first
        period: 500ms
        max_gap: 3
        points:
          - {name: temperature, table: input, address: 0x0010, type: float32, unit: degC, deadband: 0.2}
          - {name: energy, table: holding, address: 0x0020, type: uint64, byte_order: little, word_order: high_first}
          - {name: mode, table: holding, address: 0x0030, writable: true, min: 0, max: 3,
             enum: {0: off, 1: heat, 0x2: cool}}
          - {name: alarm_bit, table: holding, address: 0x0031, bit: 4}
          - {name: run, table: coils, address: 7, period: 2s}
          - {name: serial, table: input, address: 0x0100, type: string, count: 8}
          - {name: voltage, table: input, address: 0x0040, type: int16, scale: 0.1, offset: -5}
        alarms:
          - {name: too_hot, point: temperature, above: 80, hysteresis: 2, severity: critical, text: Overheated}
          - {name: heating, point: mode, equals: heat}
          - {name: fault, point: voltage, bit: 15}
          - {name: stopped, point: run, not_equals: 1}
)"));
    const DeviceConfig& device = only_device(*config);
    CHECK(device.type == DeviceType::modbus);
    CHECK(device.type_name == "modbus");
    CHECK(device.definition_file.empty());
    CHECK(device.period == 500ms);
    CHECK(device.word_order == WordOrder::low_first);
    CHECK(device.blocks.empty());
    const auto& model = device.points;
    CHECK(model.max_gap == 3);
    REQUIRE(model.points.size() == 7);
    const auto& temperature = model.points[0];
    CHECK(temperature.type == PointType::float32);
    CHECK(temperature.table == RegisterTable::input);
    CHECK(temperature.address == 0x10);
    CHECK(temperature.word_order == WordOrder::low_first);  // the device's
    CHECK(temperature.byte_order == ByteOrder::big);
    CHECK(temperature.period == 500ms);
    CHECK(temperature.unit == "degC");
    CHECK(temperature.deadband == 0.2);
    CHECK_FALSE(temperature.writable);
    CHECK(temperature.width() == 2);
    CHECK(model.points[1].word_order == WordOrder::high_first);  // its own
    CHECK(model.points[1].byte_order == ByteOrder::little);
    CHECK(model.points[1].width() == 4);
    const auto& mode = model.points[2];
    CHECK(mode.type == PointType::uint16);  // the register default
    CHECK(mode.writable);
    CHECK(mode.min == 0);
    CHECK(mode.max == 3);
    REQUIRE(mode.labels.size() == 3);
    CHECK(mode.labels[2].value == 2);
    CHECK(mode.labels[2].label == "cool");
    CHECK(model.points[3].type == PointType::boolean);  // bit: makes a bool
    CHECK(model.points[3].bit == 4);
    CHECK(model.points[4].type == PointType::boolean);  // a coil is a bool
    CHECK(model.points[4].period == 2s);
    CHECK(model.points[5].count == 8);
    CHECK(model.points[5].width() == 8);
    CHECK(model.points[6].scale == 0.1);
    CHECK(model.points[6].offset == -5);
    REQUIRE(model.alarms.size() == 4);
    CHECK(model.alarms[0].condition == AlarmCondition::above);
    CHECK(model.alarms[0].threshold == 80);
    CHECK(model.alarms[0].hysteresis == 2);
    CHECK(model.alarms[0].severity == AlarmSeverity::critical);
    CHECK(model.alarms[0].text == "Overheated");
    CHECK(model.alarms[1].condition == AlarmCondition::equals);
    CHECK(model.alarms[1].threshold == 1);  // the label's code
    CHECK(model.alarms[1].severity == AlarmSeverity::warning);
    CHECK(model.alarms[2].condition == AlarmCondition::bit);
    CHECK(model.alarms[2].bit == 15);
    CHECK(model.alarms[3].condition == AlarmCondition::not_equals);
}

TEST_CASE("a generic device needs points or blocks; points and blocks combine") {
    CHECK_REPORTS(device_with(""), "lines[0].devices[0].blocks", 6, 9, "needs points or register blocks");
    CHECK_REPORTS(device_with("        points: []\n"), "lines[0].devices[0].blocks", 6, 9, "needs points");
    const auto config = load_ok(device_with(R"(        period: 250ms
        points: [{name: p, table: holding, address: 0}]
        blocks: [{table: holding, address: 0x100, count: 4}, {table: input, address: 0, count: 1, period: 2s}]
)"));
    const auto& device = only_device(*config);
    REQUIRE(device.blocks.size() == 2);
    CHECK(device.blocks[0].period == 250ms);  // the device's period
    CHECK(device.blocks[1].period == 2s);
    CHECK(device.points.points.size() == 1);
}

TEST_CASE("points, alarms, period and max_gap belong to generic devices") {
    const std::string keys = "        points: [{name: p, table: holding, address: 0}]\n"
                             "        alarms: []\n"
                             "        max_gap: 2\n"
                             "        period: 1s\n";
    const auto diagnostics = diagnostics_of(device_with(keys, "excd203mb"));
    INFO(dump(diagnostics));
    for (const char* key : {"points", "alarms", "max_gap", "period"}) {
        const auto found = find_diagnostic(diagnostics, std::string("lines[0].devices[0].") + key);
        REQUIRE_MESSAGE(found.has_value(), key);
        CHECK(found->message.find("apply only to generic modbus devices and device definitions") != std::string::npos);
    }
    CHECK_REPORTS(device_with("        max_gap: 125\n        blocks: [{table: holding, address: 0, count: 1}]\n"),
                  "lines[0].devices[0].max_gap", 10, 18, "out of range", "0..124");
    CHECK_REPORTS(device_with("        period: 0ms\n        blocks: [{table: holding, address: 0, count: 1}]\n"),
                  "lines[0].devices[0].period", 10, 17, "out of range");
}

TEST_CASE("each key of a point is checked where it is written") {
    const std::string p = "lines[0].devices[0].points[0].";
    SUBCASE("names: snake_case, required") {
        CHECK_REPORTS(device_with("        points: [{name: Supply-V, table: holding, address: 0}]\n"), p + "name", 10, 25,
                      "not a snake_case name");
        CHECK_REPORTS(device_with("        points: [{table: holding, address: 0}]\n"), p + "name", 10, 18,
                      "required key is missing");
        CHECK_REPORTS(one_point("address: 0"), p + "table", 11, 13, "required key is missing");
        CHECK_REPORTS(one_point("table: holding"), p + "address", 11, 13, "required key is missing");
        CHECK_REPORTS(one_point("table: holding, address: 0x10000"), p + "address", 11, 48, "out of range");
        CHECK_REPORTS(one_point("table: holdings, address: 0"), p + "table", 11, 30, "holding");
        CHECK_REPORTS(one_point("table: holding, address: 0, type: float16"), p + "type", 11, 57, "float32");
        CHECK_REPORTS(one_point("table: holding, address: 0, unknown: 1"), p + "unknown", 11, 51,
                      "unknown key 'unknown'");
    }
    SUBCASE("table and type fit") {
        CHECK_REPORTS(one_point("table: coils, address: 0, type: uint16"), p + "type", 11, 55, "holds single bits");
        CHECK(diagnostics_of(one_point("table: holding, address: 0, type: bool")).empty());  // the whole register
        CHECK_REPORTS(one_point("table: holding, address: 0, bit: 16"), p + "bit", 11, 56, "out of range", "0..15");
        CHECK_REPORTS(one_point("table: coils, address: 0, bit: 1"), p + "bit", 11, 54, "bit applies to holding and input");
        CHECK_REPORTS(one_point("table: input, address: 0, type: int32, bit: 1"), p + "type", 11, 55,
                      "a point with bit: is a bool");
        CHECK(diagnostics_of(one_point("table: discrete_inputs, address: 0, type: bool")).empty());
        CHECK(diagnostics_of(one_point("table: input, address: 0, type: bool, bit: 15")).empty());
    }
    SUBCASE("count: strings only, 1..125") {
        CHECK_REPORTS(one_point("table: input, address: 0, type: string"), p + "count", 11, 13, "required key");
        CHECK_REPORTS(one_point("table: input, address: 0, type: string, count: 126"), p + "count", 11, 70,
                      "out of range", "1..125");
        CHECK_REPORTS(one_point("table: input, address: 0, type: int32, count: 2"), p + "count", 11, 69,
                      "count applies only to string points", "takes 2 register(s)");
    }
    SUBCASE("the value must end by 0xFFFF") {
        CHECK_REPORTS(one_point("table: input, address: 0xFFFE, type: float64"), p + "address", 11, 46,
                      "runs past 0xFFFF");
        CHECK(diagnostics_of(one_point("table: input, address: 0xFFFC, type: float64")).empty());
    }
    SUBCASE("numbers: scale, offset, min, max, deadband, enum") {
        CHECK_REPORTS(one_point("table: input, address: 0, scale: 0"), p + "scale", 11, 56, "non-zero");
        CHECK_REPORTS(one_point("table: coils, address: 0, scale: 2"), p + "scale", 11, 56, "numeric points");
        CHECK_REPORTS(one_point("table: input, address: 0, type: string, count: 2, max: 2"), p + "max", 11, 78,
                      "numeric points");
        CHECK_REPORTS(one_point("table: holding, address: 0, writable: true, min: 5, max: 1"), p + "max", 11, 80,
                      "below min", "min <= max");
        CHECK_REPORTS(one_point("table: input, address: 0, deadband: -1"), p + "deadband", 11, 59, ">= 0");
        CHECK_REPORTS(one_point("table: input, address: 0, type: float32, enum: {0: a}"), p + "enum", 11, 70,
                      "integer and bool points");
        CHECK_REPORTS(one_point("table: input, address: 0, enum: {x: a}"), p + "enum.x", 11, 56, "not an integer");
        CHECK_REPORTS(one_point("table: input, address: 0, enum: {0: a, 0x0: b}"), p + "enum.0x0", 11, 62,
                      "already labelled 'a'");
        CHECK_REPORTS(one_point("table: holding, address: 0, writable: true, enum: {0: a, 1: a}"), p + "enum.1", 11, 83,
                      "already used for 0", "writable point");
        // Read-only: two codes may read alike (two spellings of one state).
        CHECK(diagnostics_of(one_point("table: input, address: 0, enum: {0: a, 1: a}")).empty());
        CHECK_REPORTS(one_point("table: input, address: 0, scale: abc"), p + "scale", 11, 56, "number");
    }
    SUBCASE("writable: coils and holding only") {
        CHECK_REPORTS(one_point("table: input, address: 0, writable: true"), p + "writable", 11, 59, "read-only",
                      "table: holding");
        CHECK_REPORTS(one_point("table: discrete_inputs, address: 0, writable: true"), p + "writable", 11, 69,
                      "table: coils");
    }
    SUBCASE("enum_other and enum_code: with an enum only") {
        CHECK_REPORTS(one_point("table: input, address: 0, enum_other: x"), p + "enum_other", 11, 61,
                      "only to a point with enum");
        CHECK_REPORTS(one_point("table: input, address: 0, enum_code: false"), p + "enum_code", 11, 60,
                      "only to a point with enum");
        CHECK_REPORTS(one_point("table: input, address: 0, enum: {0: a}, enum_other: ''"), p + "enum_other", 11, 75,
                      "the label is empty");
        CHECK(diagnostics_of(one_point("table: input, address: 0, enum: {0: a}, enum_other: b, enum_code: false"))
                  .empty());
    }
    SUBCASE("invert: bool points; format: hex: integer points shown as a text, read-only") {
        CHECK_REPORTS(one_point("table: input, address: 0, invert: true"), p + "invert", 11, 57,
                      "invert applies only to bool points");
        CHECK(diagnostics_of(one_point("table: input, address: 0, bit: 3, invert: true")).empty());
        CHECK(diagnostics_of(one_point("table: coils, address: 0, invert: true, writable: true")).empty());
        CHECK_REPORTS(one_point("table: input, address: 0, type: float32, format: hex"), p + "format", 11, 72,
                      "format: hex applies only to integer points");
        CHECK_REPORTS(one_point("table: input, address: 0, format: octal"), p + "format", 11, 57, "number, hex");
        CHECK_REPORTS(one_point("table: input, address: 0, format: hex, scale: 2"), p + "scale", 11, 69,
                      "shows its registers as a text");
        CHECK_REPORTS(one_point("table: holding, address: 0, format: hex, writable: true"), p + "writable", 11, 74,
                      "is read-only");
        CHECK_REPORTS(one_point("table: input, address: 0, format: hex, enum: {0: a}"), p + "enum", 11, 68,
                      "not a label");
        CHECK(diagnostics_of(one_point("table: input, address: 0, type: uint32, format: hex")).empty());
        CHECK(diagnostics_of(one_point("table: input, address: 0, format: number, scale: 2")).empty());
    }
    SUBCASE("format: a template of the point's registers") {
        CHECK(diagnostics_of(one_point("table: input, address: 0, count: 4, format: 'V{0}.{1}.{2}.{3}'")).empty());
        CHECK(diagnostics_of(one_point("table: input, address: 0, type: int16, count: 2, format: '{1:hex}/{0}'"))
                  .empty());
        CHECK_REPORTS(one_point("table: input, address: 0, format: 'V{0}'"), p + "count", 11, 13,
                      "the number of registers the format template shows");
        CHECK_REPORTS(one_point("table: input, address: 0, count: 2, format: 'V{0}.{2}'"), p + "format", 11, 67,
                      "'{2}' is not a name it may use", "{0} to {1}");
        CHECK_REPORTS(one_point("table: input, address: 0, count: 2, format: 'V{0'"), p + "format", 11, 67,
                      "never closed");
        CHECK_REPORTS(one_point("table: input, address: 0, count: 2, format: '{0:dec}'"), p + "format", 11, 67,
                      "the only style is ':hex'");
        CHECK_REPORTS(one_point("table: input, address: 0, type: uint32, count: 2, format: '{0}'"), p + "format", 11,
                      81, "applies to uint16 and int16 points");
        CHECK_REPORTS(one_point("table: input, address: 0, count: 2, format: '{0}', scale: 2"), p + "scale", 11, 81,
                      "format template");
        CHECK_REPORTS(one_point("table: holding, address: 0, count: 2, format: '{0}', writable: true"), p + "writable",
                      11, 86, "read-only");
        CHECK_REPORTS(one_point("table: input, address: 0xFFFF, count: 2, format: '{0}'"), p + "address", 11, 46,
                      "runs past 0xFFFF");
        CHECK_REPORTS(one_point("table: input, address: 0, bit: 1, format: '{0}'"), p + "format", 11, 65,
                      "a bit is a bool");
    }
    SUBCASE("enum_other may show the code") {
        CHECK(diagnostics_of(one_point("table: input, address: 0, enum: {0: a}, enum_other: 'unknown ({value:hex})'"))
                  .empty());
        CHECK(diagnostics_of(one_point("table: input, address: 0, enum: {0: a}, enum_other: 'code {value}'")).empty());
        CHECK_REPORTS(one_point("table: input, address: 0, enum: {0: a}, enum_other: 'code {0}'"), p + "enum_other",
                      11, 75, "'{0}' is not a name it may use", "{value} or {value:hex}");
    }
    SUBCASE("period in range") {
        CHECK_REPORTS(one_point("table: input, address: 0, period: 2h"), p + "period", 11, 57, "out of range");
    }
}

TEST_CASE("points of a device: unique names, no overlap of different values") {
    const std::string points = "lines[0].devices[0].points";
    CHECK_REPORTS(device_with(R"(        points:
          - {name: a, table: holding, address: 0}
          - {name: a, table: holding, address: 1}
)"),
                  points + "[1].name", 12, 20, "'a' is already used by lines[0].devices[0].points[0] (test.yaml:11)");
    CHECK_REPORTS(device_with(R"(        points:
          - {name: a, table: holding, address: 0, type: float32}
          - {name: b, table: holding, address: 1}
)"),
                  points + "[1]", 12, 13, "'b' (uint16, 0x0001) overlaps 'a' (float32, 0x0000-0x0001)",
                  "same type and width");
    CHECK_REPORTS(device_with(R"(        points:
          - {name: a, table: holding, address: 0}
          - {name: b, table: holding, address: 0, bit: 3}
)"),
                  points + "[1]", 12, 13, "overlaps");
    // The same registers in another table, identical points, bit points together.
    CHECK(diagnostics_of(device_with(R"(        points:
          - {name: a, table: holding, address: 0, type: float32}
          - {name: b, table: input, address: 0, type: float32}
          - {name: c, table: holding, address: 0, type: float32, scale: 10}
          - {name: d, table: holding, address: 2, bit: 0}
          - {name: e, table: holding, address: 2, bit: 1}
          - {name: f, table: coils, address: 0}
)")).empty());
}

TEST_CASE("alarms name a point they can be evaluated on") {
    const std::string a = "lines[0].devices[0].alarms[0].";
    const auto with_alarm = [](std::string_view alarm) {
        return device_with(std::string(R"(        points:
          - {name: t, table: input, address: 0, type: float32}
          - {name: s, table: input, address: 2, type: string, count: 2}
          - {name: on, table: coils, address: 0}
          - {name: m, table: holding, address: 0, enum: {0: off, 1: heat}}
        alarms:
          - )") + std::string(alarm) + "\n");
    };
    CHECK_REPORTS(with_alarm("{name: x, point: nope, above: 1}"), a + "point", 16, 30, "no point 'nope'", "t, s, on, m");
    CHECK_REPORTS(with_alarm("{name: x, point: t}"), "lines[0].devices[0].alarms[0]", 16, 13, "has no condition");
    CHECK_REPORTS(with_alarm("{name: x, point: t, above: 1, below: 0}"), "lines[0].devices[0].alarms[0]", 16, 13,
                  "several conditions");
    CHECK_REPORTS(with_alarm("{name: x, point: s, above: 1}"), a + "above", 16, 40, "compare numbers",
                  "'s' is string");
    CHECK_REPORTS(with_alarm("{name: x, point: on, below: 1}"), a + "below", 16, 41, "compare numbers");
    CHECK_REPORTS(with_alarm("{name: x, point: t, bit: 1}"), a + "bit", 16, 38, "integer points");
    CHECK_REPORTS(with_alarm("{name: x, point: m, bit: 16}"), a + "bit", 16, 38, "beyond the 16 bits");
    CHECK_REPORTS(with_alarm("{name: x, point: m, equals: cool}"), a + "equals", 16, 41,
                  "neither a number nor a label");
    CHECK_REPORTS(with_alarm("{name: x, point: s, equals: 1}"), a + "equals", 16, 41, "numbers or enum labels");
    CHECK_REPORTS(with_alarm("{name: x, point: t, above: 1, hysteresis: -1}"), a + "hysteresis", 16, 55, ">= 0");
    CHECK_REPORTS(with_alarm("{name: x, point: t, above: 1, severity: fatal}"), a + "severity", 16, 53, "critical");
    CHECK_REPORTS(with_alarm("{name: X, point: t, above: 1}"), a + "name", 16, 20, "snake_case");
    CHECK_REPORTS(with_alarm("{point: t, above: 1}"), a + "name", 16, 13, "required key");
    CHECK_REPORTS(with_alarm("{name: x, point: t, above: 1, text: 'hot {valu}'}"), a + "text", 16, 49,
                  "a brace that is not {value}");
    CHECK_REPORTS(with_alarm("{name: x, point: t, above: 1, text: 'hot }'}"), a + "text", 16, 49,
                  "a brace that is not {value}");
    CHECK(diagnostics_of(with_alarm("{name: x, point: t, above: 1, text: 'hot: {value} (max 1)'}")).empty());
    CHECK_REPORTS(with_alarm("{name: x, point: t, above: 1, source: ''}"), a + "source", 16, 51, "one line");
    CHECK(diagnostics_of(with_alarm("{name: x, point: t, above: 1, source: terminal X3}")).empty());
    CHECK(diagnostics_of(with_alarm("{name: x, point: m, not_equals: off}")).empty());
    CHECK(diagnostics_of(with_alarm("{name: x, point: on, equals: 1}")).empty());
    // A point shown through a format template is a text: nothing to compare.
    CHECK_REPORTS(device_with(R"(        points:
          - {name: v, table: input, address: 4, count: 2, format: 'V{0}.{1}'}
        alarms:
          - {name: x, point: v, equals: 1}
)"), a + "point", 13, 30, "shows its registers as a text");
    CHECK_REPORTS(device_with(R"(        points: [{name: t, table: input, address: 0}]
        alarms:
          - {name: x, point: t, above: 1}
          - {name: x, point: t, below: 0}
)"),
                  "lines[0].devices[0].alarms[1].name", 13, 20, "'x' is already used");
}
