// Device definition files (docs/devices.md): the `definitions:` search, a device
// naming one with `type:`, inline points added to it, problems in a definition
// reported at file:line:col of that file, and the public loaders the simulator and
// scan use.

#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include "config/builtin_definitions.hpp"
#include "config/device_definition.hpp"
#include "config_test_support.hpp"
#include "temp_dir.hpp"

using namespace fieldbridge::config;
using namespace fieldbridge::config::test;
using fieldbridge::core::AlarmCondition;
using fieldbridge::core::PointType;
using namespace std::chrono_literals;

namespace {

void write_file(const std::filesystem::path& file, std::string_view text) {
    std::filesystem::create_directories(file.parent_path());
    std::ofstream(file, std::ios::binary) << yaml_text(text);
}

/// A thermostat-like definition (the worked example of docs/devices.md, smaller).
constexpr std::string_view thermostat = R"(
name: thermostat
description: A room thermostat
word_order: low_first
period: 2s
max_gap: 4
points:
  - {name: temperature, table: input, address: 0x0000, type: float32, unit: degC}
  - {name: runtime, table: input, address: 0x0002, type: int32, unit: s}
  - {name: mode, table: holding, address: 0x0010, writable: true, enum: {0: off, 1: heat, 2: cool}}
  - {name: status, table: input, address: 0x0004}
  - {name: setpoint, table: holding, address: 0x0011, type: int16, scale: 0.1, writable: true, min: 5, max: 30}
alarms:
  - {name: sensor_fault, point: status, bit: 0, severity: error, text: Sensor broken}
blocks:
  - {table: holding, address: 0x0100, count: 2}
identify: {table: input, address: 0x00F0, count: 2, expect: [0x5448, 1]}
)";

/// The configuration of one device of type @p type (config_test_support.hpp): the
/// device's `type` on line 8 when @p top is one line.
std::string config_text(std::string_view type, std::string_view extra = "", std::string_view top = "") {
    return one_device_config(type, extra, top);
}

std::vector<Diagnostic> diagnostics_in(const std::filesystem::path& config_file, std::string_view text) {
    write_file(config_file, text);
    try {
        (void)load_config_file(config_file);
        return {};
    } catch (const ConfigError& e) {
        return e.diagnostics();
    }
}

std::shared_ptr<const Config> load_in(const std::filesystem::path& config_file, std::string_view text) {
    write_file(config_file, text);
    try {
        return load_config_file(config_file);
    } catch (const ConfigError& e) {
        FAIL("expected the config to load, got:\n" << e.what());
    }
    return nullptr;
}

/// The one diagnostic of @p file at @p line : @p column that says every fragment.
void require_diagnostic(const std::vector<Diagnostic>& diagnostics, const std::filesystem::path& file, int line,
                        int column, std::initializer_list<std::string_view> fragments) {
    INFO("diagnostics:\n" << dump(diagnostics));
    bool found = false;
    for (const auto& d : diagnostics) {
        bool all = d.file == file.string() && d.line == line && d.column == column;
        for (const auto fragment : fragments) {
            all = all && d.message.find(fragment) != std::string::npos;
        }
        found = found || all;
    }
    CHECK_MESSAGE(found, "no diagnostic at " << file.string() << ":" << line << ":" << column);
}

}  // namespace

TEST_CASE("a device of a definition: the definition's points, then the inline ones, with their defaults") {
    const fieldbridge::test::TempDir dir("fb-definitions");
    write_file(dir.path() / "devices" / "thermostat.yaml", thermostat);
    const auto config = load_in(dir.path() / "gw.yaml", config_text("thermostat",
                                                                     "        period: 500ms\n"
                                                                     "        points: [{name: extra, table: holding, address: 0x0020, type: uint32}]\n"
                                                                     "        alarms: [{name: too_cold, point: temperature, below: 5}]\n"
                                                                     "        blocks: [{table: coils, address: 0, count: 8}]\n",
                                                                     "definitions: [devices]\n"));
    const DeviceConfig& device = config->lines.at(0).devices.at(0);
    CHECK(device.type == DeviceType::modbus);
    CHECK(device.type_name == "thermostat");
    CHECK(device.definition_file == (dir.path() / "devices" / "thermostat.yaml").string());
    CHECK(device.word_order == WordOrder::low_first);  // the definition's
    CHECK(device.period == 500ms);                     // the device's over the definition's
    const auto& model = device.points;
    CHECK(model.max_gap == 4);
    REQUIRE(model.points.size() == 6);
    CHECK(model.points[0].name == "temperature");
    CHECK(model.points[0].word_order == WordOrder::low_first);
    CHECK(model.points[0].period == 500ms);
    CHECK(model.points[4].min == 5);
    CHECK(model.points[4].scale == 0.1);
    CHECK(model.points[5].name == "extra");
    CHECK(model.points[5].word_order == WordOrder::low_first);
    REQUIRE(model.alarms.size() == 2);
    CHECK(model.alarms[0].name == "sensor_fault");
    CHECK(model.alarms[0].condition == AlarmCondition::bit);
    CHECK(model.alarms[1].name == "too_cold");
    REQUIRE(device.blocks.size() == 2);  // the definition's, then the device's
    CHECK(device.blocks[0].address == 0x0100);
    CHECK(device.blocks[0].period == 500ms);
    CHECK(device.blocks[1].table == RegisterTable::coils);
}

TEST_CASE("definitions: the first directory that has the file wins; relative to the config's folder") {
    const fieldbridge::test::TempDir dir("fb-definitions");
    write_file(dir.path() / "site" / "thermostat.yaml",
               "name: thermostat\npoints: [{name: only_site, table: input, address: 0}]\n");
    write_file(dir.path() / "shipped" / "thermostat.yaml", thermostat);
    write_file(dir.path() / "shipped" / "meter.yaml", "name: meter\npoints: [{name: kwh, table: input, address: 0}]\n");
    const auto config = load_in(dir.path() / "conf" / "gw.yaml",
                                config_text("thermostat", "", "definitions: [../site, " +
                                                                  (dir.path() / "shipped").string() + "]\n"));
    const auto& device = config->lines.at(0).devices.at(0);
    REQUIRE(device.points.points.size() == 1);
    CHECK(device.points.points[0].name == "only_site");
    CHECK(device.definition_file == (dir.path() / "site" / "thermostat.yaml").string());

    std::vector<Diagnostic> problems;
    const auto all = load_definitions({dir.path() / "site", dir.path() / "missing", dir.path() / "shipped"}, problems);
    CHECK(problems.empty());
    REQUIRE(all.size() == 2);
    CHECK(all[0].name == "thermostat");
    CHECK(all[0].points.points.at(0).name == "only_site");
    CHECK(all[1].name == "meter");
}

TEST_CASE("a type with no definition says which directories were searched, in order") {
    const fieldbridge::test::TempDir dir("fb-definitions");
    std::filesystem::create_directories(dir.path() / "a");
    const auto file = dir.path() / "gw.yaml";
    const auto diagnostics = diagnostics_in(file, config_text("acme-th20", "", "definitions: [a, b]\n"));
    require_diagnostic(diagnostics, file, 8, 15,
                       {"'acme-th20' is not a built-in type", "no device definition acme-th20.yaml was found",
                        "searched, in this order: " + (dir.path() / "a").string() + ", " +
                            (dir.path() / "b").string() + " (no such directory)"});
    // Without definitions: the defaults, site first.
    CHECK_REPORTS(config_text("acme-th20"), "lines[0].devices[0].type", 7, 15,
                  "/etc/fieldbridge/devices (no such directory), /usr/share/fieldbridge/devices");
    CHECK_REPORTS(config_text("Acme TH"), "lines[0].devices[0].type", 7, 15, "neither a built-in type");
    CHECK_REPORTS(config_text("modbus", "", "definitions: x\n"), "definitions", 1, 14, "expected a list");
}

TEST_CASE("problems in a definition are reported at file:line:col of the definition") {
    const fieldbridge::test::TempDir dir("fb-definitions");
    const auto definition = dir.path() / "d" / "bad.yaml";
    write_file(definition, R"(
name: badly
points:
  - {name: t, table: input, address: 0, type: float32}
  - {name: u, table: input, address: 1, count: 2}
  - {name: v, table: coils, address: 0, bit: 3}
  - {name: w, table: holding, address: 9, enum: {one: a}, min: 4, max: 3}
alarms:
  - {name: x, point: missing, above: 1}
identify: {table: coils, address: 0, count: 2, expect: [1]}
unknown_key: 1
)");
    const auto file = dir.path() / "gw.yaml";
    const auto diagnostics = diagnostics_in(file, config_text("bad", "", "definitions: [d]\n"));
    require_diagnostic(diagnostics, definition, 1, 7, {"differs from the file name bad.yaml", "expected name: bad"});
    require_diagnostic(diagnostics, definition, 4, 5, {"'u' (uint16, 0x0001) overlaps 't' (float32"});
    require_diagnostic(diagnostics, definition, 4, 48, {"count applies only to string points"});
    require_diagnostic(diagnostics, definition, 5, 46, {"bit applies to holding and input"});
    require_diagnostic(diagnostics, definition, 6, 50, {"not an integer"});
    require_diagnostic(diagnostics, definition, 6, 72, {"min <= max"});
    require_diagnostic(diagnostics, definition, 8, 22, {"no point 'missing'"});
    require_diagnostic(diagnostics, definition, 9, 19, {"holding or input"});
    require_diagnostic(diagnostics, definition, 9, 56, {"one value per register"});
    require_diagnostic(diagnostics, definition, 10, 1, {"unknown key 'unknown_key'"});
    require_diagnostic(diagnostics, file, 8, 15, {"the device definition", "bad.yaml has problems"});
    // The configuration's own problems come first, the definition's after them.
    REQUIRE_FALSE(diagnostics.empty());
    CHECK(diagnostics.front().file == file.string());

    CHECK_THROWS_AS((void)load_definition_file(definition), ConfigError);
    try {
        (void)load_definition_file(definition);
    } catch (const ConfigError& e) {
        CHECK(std::string(e.what()).find(definition.string() + ":1:7: name:") != std::string::npos);
    }
}

TEST_CASE("a definition that does not parse, is empty, or has nothing to read") {
    const fieldbridge::test::TempDir dir("fb-definitions");
    const auto file = dir.path() / "gw.yaml";
    write_file(dir.path() / "syntax.yaml", "name: syntax\npoints: [{name: a,\n");
    auto diagnostics = diagnostics_in(file, config_text("syntax", "", "definitions: [.]\n"));
    INFO(dump(diagnostics));
    REQUIRE(diagnostics.size() >= 2);
    CHECK(diagnostics.back().file == (dir.path() / "syntax.yaml").string());
    CHECK(diagnostics.back().message.find("YAML syntax error") != std::string::npos);
    CHECK(diagnostics.back().line > 0);

    write_file(dir.path() / "empty.yaml", "");
    diagnostics = diagnostics_in(file, config_text("empty", "", "definitions: [.]\n"));
    require_diagnostic(diagnostics, dir.path() / "empty.yaml", 1, 1, {"the device definition is empty"});

    write_file(dir.path() / "nothing.yaml", "name: nothing\ndescription: no points\n");
    diagnostics = diagnostics_in(file, config_text("nothing", "", "definitions: [.]\n"));
    require_diagnostic(diagnostics, dir.path() / "nothing.yaml", 1, 1, {"needs points (or blocks)"});
}

TEST_CASE("inline points add to the definition's: a clash of names or registers is an error in the config") {
    const fieldbridge::test::TempDir dir("fb-definitions");
    write_file(dir.path() / "thermostat.yaml", thermostat);
    const auto file = dir.path() / "gw.yaml";
    const auto definition = (dir.path() / "thermostat.yaml").string();
    auto diagnostics = diagnostics_in(file, config_text("thermostat",
                                                        "        points:\n"
                                                        "          - {name: mode, table: holding, address: 0x0200}\n"
                                                        "          - {name: half, table: input, address: 0x0001}\n"
                                                        "        alarms: [{name: sensor_fault, point: half, above: 1}]\n"
                                                        "        blocks: [{table: holding, address: 0x0101, count: 1}]\n",
                                                        "definitions: [.]\n"));
    require_diagnostic(diagnostics, file, 12, 20,
                       {"'mode' is already used by points[2] (" + definition + ":9)"});
    require_diagnostic(diagnostics, file, 13, 13, {"'half' (uint16, 0x0001) overlaps 'temperature'"});
    require_diagnostic(diagnostics, file, 14, 25, {"'sensor_fault' is already used"});
    require_diagnostic(diagnostics, file, 15, 18, {"overlaps blocks[0] of the definition"});
}

TEST_CASE("load_definition_file gives the definition with its defaults") {
    const fieldbridge::test::TempDir dir("fb-definitions");
    write_file(dir.path() / "thermostat.yaml", thermostat);
    const auto definition = load_definition_file(dir.path() / "thermostat.yaml");
    CHECK(definition.name == "thermostat");
    CHECK(definition.description == "A room thermostat");
    CHECK(definition.period == 2s);
    CHECK(definition.word_order == WordOrder::low_first);
    REQUIRE(definition.points.points.size() == 5);
    CHECK(definition.points.points[0].type == PointType::float32);
    CHECK(definition.points.points[0].period == 2s);
    CHECK(definition.points.points[0].word_order == WordOrder::low_first);
    REQUIRE(definition.blocks.size() == 1);
    CHECK(definition.blocks[0].period == 2s);
    REQUIRE(definition.identify.has_value());
    CHECK(definition.identify->table == RegisterTable::input);
    CHECK(definition.identify->address == 0x00F0);
    CHECK(definition.identify->count == 2);
    CHECK(definition.identify->expect == std::vector<std::uint16_t>{0x5448, 1});
    CHECK_THROWS_AS((void)load_definition_file(dir.path() / "missing.yaml"), ConfigError);
}

TEST_CASE("the shipped definitions (config/devices) load without a problem; the worked example as documented") {
    std::vector<Diagnostic> problems;
    const auto shipped = load_definitions({FIELDBRIDGE_SHIPPED_DEFINITIONS}, problems);
    INFO(dump(problems));
    CHECK(problems.empty());
    const auto example = std::find_if(shipped.begin(), shipped.end(),
                                      [](const DeviceDefinition& d) { return d.name == "example-thermostat"; });
    REQUIRE(example != shipped.end());
    const auto& points = example->points.points;
    REQUIRE(points.size() == 6);
    CHECK(points[0].type == PointType::float32);
    CHECK(points[1].type == PointType::int32);
    CHECK(points[1].period == 10s);
    CHECK(points[3].labels.size() == 4);
    CHECK(points[4].writable);
    CHECK(points[4].min == 5);
    CHECK(points[4].max == 30);
    REQUIRE(example->points.alarms.size() == 2);
    CHECK(example->points.alarms[0].condition == AlarmCondition::bit);
    REQUIRE(example->identify.has_value());
    CHECK(example->identify->expect == std::vector<std::uint16_t>{0x5448});
}

// ---- the built-in types as definitions (docs/devices.md, "Built-in types") --------

namespace {

std::string shipped_text(std::string_view name) {
    std::ifstream in(std::filesystem::path(FIELDBRIDGE_SHIPPED_DEFINITIONS) / (std::string(name) + ".yaml"),
                     std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// @p text with its one @p from replaced by @p to.
std::string replaced(std::string text, std::string_view from, std::string_view to) {
    const auto at = text.find(from);
    REQUIRE_MESSAGE(at != std::string::npos, "the shipped text has no '" << from << "'");
    return text.replace(at, from.size(), to);
}

/// Line and column (1-based) of @p needle in @p text.
std::pair<int, int> position_of(std::string_view text, std::string_view needle) {
    const auto at = text.find(needle);
    REQUIRE(at != std::string_view::npos);
    const auto line_start = text.rfind('\n', at);
    const auto line = 1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n');
    const auto column = at - (line_start == std::string_view::npos ? 0 : line_start + 1) + 1;
    return {static_cast<int>(line), static_cast<int>(column)};
}

const fieldbridge::core::RegisterDef& row_named(const std::vector<fieldbridge::core::RegisterDef>& rows,
                                                std::string_view name) {
    const auto it = std::find_if(rows.begin(), rows.end(), [&](const auto& r) { return r.name == name; });
    REQUIRE_MESSAGE(it != rows.end(), "no register " << name);
    return *it;
}

constexpr std::string_view excd_abs_row =
    "{name: abs, address: 0x0100, width: 2, access: write, motion: true, min: -8300000, max: 8300000}";

/// The names of a definition's points, in its order (the MQTT fields).
std::vector<std::string> point_names(const DeviceDefinition& definition) {
    std::vector<std::string> names;
    for (const auto& point : definition.points.points) names.push_back(point.name);
    return names;
}

}  // namespace

TEST_CASE("every built-in type's compiled-in definition is its shipped file in config/devices") {
    REQUIRE_FALSE(builtin_definition_texts().empty());
    for (const BuiltinText& builtin : builtin_definition_texts()) {
        INFO(builtin.name);
        CHECK(builtin.text == shipped_text(builtin.name));
        const auto type = fieldbridge::core::parse<DeviceType>(builtin.name);
        REQUIRE(type.has_value());
        const DeviceDefinition* compiled = builtin_definition(*type);
        REQUIRE(compiled != nullptr);
        CHECK(compiled->behaviour == type);
        CHECK(compiled->file == builtin_definition_path(builtin.name));
        DeviceDefinition file = load_definition_file(std::filesystem::path(FIELDBRIDGE_SHIPPED_DEFINITIONS) /
                                                     (std::string(builtin.name) + ".yaml"));
        file.file = compiled->file;
        CHECK(file == *compiled);
    }
    CHECK(builtin_definition(DeviceType::modbus) == nullptr);
}

TEST_CASE("excd203mb's definition: the register map of docs/registers.md") {
    const DeviceDefinition* excd = builtin_definition(DeviceType::excd203mb);
    REQUIRE(excd != nullptr);
    const auto& rows = excd->registers;
    CHECK(rows.size() == 77);
    const auto& abs = row_named(rows, "abs");
    CHECK(abs.address == 0x0100);
    CHECK(abs.width == 2);
    CHECK(abs.access == fieldbridge::core::Access::write);
    CHECK(abs.is_signed);
    CHECK(abs.min == -8'300'000);
    CHECK(abs.motion);
    CHECK(row_named(rows, "jog stop").stop_value == 0);
    CHECK(row_named(rows, "save").protect);
    CHECK(row_named(rows, "n").count == 99);
    CHECK(row_named(rows, "ver").max == 0xFFFF'FFFF);
    CHECK_FALSE(row_named(rows, "ver").is_signed);
}

TEST_CASE("a built-in type without a file of its name uses the compiled-in definition") {
    const fieldbridge::test::TempDir dir("fb-definitions");
    std::filesystem::create_directories(dir.path() / "devices");
    const auto config = load_in(dir.path() / "gw.yaml", config_text("excd203mb", "", "definitions: [devices]\n"));
    const DeviceConfig& device = config->lines.at(0).devices.at(0);
    CHECK(device.type == DeviceType::excd203mb);
    CHECK(device.registers.empty());
    CHECK(device.definition_file.empty());
}

TEST_CASE("an operator's copy of a built-in definition replaces the compiled-in one") {
    const fieldbridge::test::TempDir dir("fb-definitions");
    const auto copy = dir.path() / "devices" / "excd203mb.yaml";
    write_file(copy, replaced(shipped_text("excd203mb"), excd_abs_row,
                              "{name: abs, address: 0x0100, width: 2, access: write, motion: true, min: 0, "
                              "max: 100000}"));
    const auto config = load_in(dir.path() / "gw.yaml", config_text("excd203mb", "", "definitions: [devices]\n"));
    const DeviceConfig& device = config->lines.at(0).devices.at(0);
    CHECK(device.type == DeviceType::excd203mb);
    CHECK(device.definition_file == copy.string());
    REQUIRE(device.registers.size() == 77);
    CHECK(row_named(device.registers, "abs").min == 0);
    CHECK(row_named(device.registers, "abs").max == 100000);
    CHECK_FALSE(row_named(device.registers, "abs").is_signed);
}

TEST_CASE("a site's variant of a built-in type: a definition of its own name with behaviour:") {
    const fieldbridge::test::TempDir dir("fb-definitions");
    write_file(dir.path() / "devices" / "excd-slow.yaml",
               replaced(shipped_text("excd203mb"), "name: excd203mb\n", "name: excd-slow\n"));
    const auto config = load_in(dir.path() / "gw.yaml", config_text("excd-slow", "", "definitions: [devices]\n"));
    const DeviceConfig& device = config->lines.at(0).devices.at(0);
    CHECK(device.type == DeviceType::excd203mb);
    CHECK(device.type_name == "excd-slow");
    CHECK(device.registers.size() == 77);
}

TEST_CASE("a broken copy of a built-in definition is refused at file:line:col of the copy") {
    const fieldbridge::test::TempDir dir("fb-definitions");
    const auto copy = dir.path() / "devices" / "excd203mb.yaml";
    SUBCASE("a value out of range") {
        const std::string text = replaced(shipped_text("excd203mb"), "{name: hdir, address: 0x0000, access: "
                                                                     "read_write, min: 0, max: 1}",
                                          "{name: hdir, address: 0x0000, access: read_write, min: 0, max: 0x10000}");
        write_file(copy, text);
        const auto [line, column] = position_of(text, "0x10000}");
        const auto diagnostics = diagnostics_in(dir.path() / "gw.yaml",
                                                config_text("excd203mb", "", "definitions: [devices]\n"));
        require_diagnostic(diagnostics, copy, line, column, {"65536 is out of range", "0..65535"});
        require_diagnostic(diagnostics, dir.path() / "gw.yaml", 8, 15,
                           {"replaces the built-in excd203mb", "has problems", "remove the file"});
    }
    SUBCASE("two rows over one register") {
        const std::string text = replaced(shipped_text("excd203mb"), "{name: hvs, address: 0x0001,",
                                          "{name: hvs, address: 0x0000,");
        write_file(copy, text);
        const auto [line, column] = position_of(text, "{name: hvs");
        require_diagnostic(diagnostics_in(dir.path() / "gw.yaml",
                                          config_text("excd203mb", "", "definitions: [devices]\n")),
                           copy, line, column, {"overlap", "registers[0]"});
    }
    SUBCASE("without behaviour:") {
        const std::string text = replaced(shipped_text("excd203mb"), "behaviour: excd203mb\n", "");
        write_file(copy, text);
        const auto [line, column] = position_of(text, "- {name: hdir");
        const auto diagnostics = diagnostics_in(dir.path() / "gw.yaml",
                                                config_text("excd203mb", "", "definitions: [devices]\n"));
        require_diagnostic(diagnostics, copy, line, column, {"registers: describe a built-in type's map"});
        require_diagnostic(diagnostics, dir.path() / "gw.yaml", 8, 15, {"replaces the built-in excd203mb"});
    }
}

TEST_CASE("an unknown behaviour hook is refused with the known ones") {
    const fieldbridge::test::TempDir dir("fb-definitions");
    const auto file = dir.path() / "devices" / "acme.yaml";
    write_file(file, "name: acme\n"
                     "behaviour: acme-gripper\n"
                     "registers: [{name: x, address: 0, access: read}]\n");
    const auto diagnostics = diagnostics_in(dir.path() / "gw.yaml", config_text("acme", "", "definitions: [devices]\n"));
    require_diagnostic(diagnostics, file, 2, 12,
                       {"'acme-gripper' is not allowed", "hiwin-xeg, excd203mb, wtec-rtu, wtec-ascii"});
    CHECK(diagnostics.size() == 2);  // and the device's line that names the definition
}

TEST_CASE("behaviour: takes registers, and points of them for its state; not blocks or identify") {
    const fieldbridge::test::TempDir dir("fb-definitions");
    const auto hook = dir.path() / "devices" / "hook.yaml";
    write_file(hook, "name: hook\n"
                     "behaviour: excd203mb\n"
                     "registers: [{name: x, address: 0, access: read}, {name: w, address: 2, access: write}]\n"
                     "blocks: [{table: holding, address: 0, count: 1}]\n"
                     "points:\n"
                     "  - {name: y, table: holding, address: 1}\n"
                     "  - {name: z, table: holding, address: 2}\n"
                     "  - {name: v, table: holding, address: 0, writable: true, min: 0, period: 2s}\n"
                     "  - {name: u, table: input, address: 0}\n");
    const auto diagnostics = diagnostics_in(dir.path() / "gw.yaml", config_text("hook", "", "definitions: [devices]\n"));
    require_diagnostic(diagnostics, hook, 4, 9, {"describes its registers:", "remove this key"});
    require_diagnostic(diagnostics, hook, 6, 40, {"holding 0x0001 is in no row of registers:", "readable row"});
    require_diagnostic(diagnostics, hook, 7, 40, {"holding 0x0002 is write-only in registers[1]"});
    require_diagnostic(diagnostics, hook, 8, 53, {"read-only", "remove writable"});
    require_diagnostic(diagnostics, hook, 8, 64, {"min limits writes", "remove it"});
    require_diagnostic(diagnostics, hook, 8, 75, {"poll: periods", "remove period"});
    require_diagnostic(diagnostics, hook, 9, 38, {"input 0x0000 is in no row of registers:"});
    const auto generic = dir.path() / "devices" / "generic.yaml";
    write_file(generic, "name: generic\n"
                        "points: [{name: y, table: holding, address: 1}]\n"
                        "registers: [{name: x, address: 0, access: read}]\n");
    require_diagnostic(diagnostics_in(dir.path() / "gw.yaml", config_text("generic", "", "definitions: [devices]\n")),
                       generic, 3, 12, {"without behaviour: is a generic device"});
}

TEST_CASE("excd203mb's state is points of its definition: the fields and the alarm of docs/mqtt.md") {
    const DeviceDefinition* excd = builtin_definition(DeviceType::excd203mb);
    REQUIRE(excd != nullptr);
    CHECK(point_names(*excd) == std::vector<std::string>{"position", "encoder", "busy", "inputs", "outputs",
                                                         "sensor", "alarm_code", "version"});
    const auto& busy = excd->points.points.at(2);
    CHECK(busy.invert);
    CHECK(busy.bit == 0);
    CHECK(excd->points.points.at(7).format == fieldbridge::core::PointFormat::hex);
    REQUIRE(excd->points.alarms.size() == 1);
    const auto& alarm = excd->points.alarms.front();
    CHECK(alarm.name == "alarm");
    CHECK(alarm.condition == AlarmCondition::not_equals);
    CHECK(alarm.severity == fieldbridge::core::AlarmSeverity::error);
    CHECK(alarm.source == "holding 0x02D6");
}

TEST_CASE("wtec-rtu's state is points of its definition: the fields and the alarms of docs/mqtt.md") {
    const DeviceDefinition* wtec = builtin_definition(DeviceType::wtec_rtu);
    REQUIRE(wtec != nullptr);
    CHECK(point_names(*wtec) == std::vector<std::string>{"init_state", "grip_state", "position_pct", "target_pct",
                                                         "force_pct", "speed_pct", "estop", "init_direction", "saved",
                                                         "device_id"});
    const auto& grip = wtec->points.points.at(1);
    CHECK(grip.enum_other == "unknown");
    CHECK(grip.labels.size() == 5);  // 11 and 0x11 are both motor_released
    CHECK_FALSE(wtec->points.points.at(7).enum_code);
    REQUIRE(wtec->points.alarms.size() == 2);
    CHECK(wtec->points.alarms.at(0).name == "init_failed");
    CHECK(wtec->points.alarms.at(0).threshold == 2);
    CHECK(wtec->points.alarms.at(1).name == "emergency_stop");
    CHECK(wtec->points.alarms.at(1).severity == fieldbridge::core::AlarmSeverity::critical);
}

TEST_CASE("hiwin-xeg's state is points of its definition: the fields and the alarms of docs/mqtt.md") {
    const DeviceDefinition* xeg = builtin_definition(DeviceType::hiwin_xeg);
    REQUIRE(xeg != nullptr);
    CHECK(point_names(*xeg) == std::vector<std::string>{"status", "position_mm", "model", "firmware", "di_in1",
                                                        "do_pos", "di_in2", "do_hold", "di_in3", "do_busy", "di_in4",
                                                        "do_alm1", "di_in5", "do_alm2", "di_in6", "do_chk1",
                                                        "di_start", "do_chk2", "di_di7", "do_chk3"});
    const auto& model = xeg->points.points.at(2);
    CHECK(model.enum_other == "unknown ({value:hex})");
    CHECK_FALSE(model.enum_code);
    const auto& firmware = xeg->points.points.at(3);
    CHECK(firmware.format == fieldbridge::core::PointFormat::text);
    CHECK(firmware.format_text == "V{0}.{1}.{2}.{3}");
    CHECK(firmware.width() == 4);
    std::vector<std::string> alarms;
    for (const auto& alarm : xeg->points.alarms) alarms.push_back(alarm.name + " " + alarm.source);
    CHECK(alarms == std::vector<std::string>{"position_alarm input 0x0301", "move_alarm input 0x0301",
                                             "home_alarm input 0x0301", "emergency_stop input 0x0301",
                                             "alm1 discrete input 0x0013", "alm2 discrete input 0x0014"});
}

TEST_CASE("wtec-ascii's state is points of its definition: the fields and the alarms of docs/mqtt.md") {
    const DeviceDefinition* wtec = builtin_definition(DeviceType::wtec_ascii);
    REQUIRE(wtec != nullptr);
    CHECK(point_names(*wtec) == std::vector<std::string>{"init_state", "grip_state", "position_pct", "target_pct",
                                                         "force_pct", "speed_pct", "estop", "init_direction",
                                                         "position_counts", "current", "enabled", "grip_code",
                                                         "homing_code", "firmware"});
    std::vector<std::string> alarms;
    for (const auto& alarm : wtec->points.alarms) alarms.push_back(alarm.name + " " + alarm.point);
    CHECK(alarms == std::vector<std::string>{"init_failed homing_code", "beyond_limit homing_code",
                                             "emergency_stop estop"});
}

TEST_CASE("an operator's copy with points: replaces the compiled-in state; one without keeps it") {
    const fieldbridge::test::TempDir dir("fb-definitions");
    const auto copy = dir.path() / "devices" / "excd203mb.yaml";
    const std::string shipped = shipped_text("excd203mb");
    write_file(copy, replaced(shipped, "{name: sensor, table: holding, address: 0x0206}",
                              "{name: sensor, table: holding, address: 0x0206, unit: mV}"));
    auto config = load_in(dir.path() / "gw.yaml", config_text("excd203mb", "", "definitions: [devices]\n"));
    const auto& state = config->lines.at(0).devices.at(0).builtin_state;
    REQUIRE(state.has_value());
    CHECK(state->points.at(5).name == "sensor");
    CHECK(state->points.at(5).unit == "mV");
    CHECK(state->alarms.size() == 1);

    // A copy made before the state was data (registers only): the compiled-in state.
    write_file(copy, shipped.substr(0, shipped.find("\npoints:")) + "\n");
    config = load_in(dir.path() / "gw.yaml", config_text("excd203mb", "", "definitions: [devices]\n"));
    CHECK_FALSE(config->lines.at(0).devices.at(0).builtin_state.has_value());
    CHECK(config->lines.at(0).devices.at(0).registers.size() == 77);
}

TEST_CASE("registers: rows of a read-only table are read-only; widths, counts and ranges are checked") {
    const fieldbridge::test::TempDir dir("fb-definitions");
    const auto file = dir.path() / "devices" / "hook.yaml";
    write_file(file, "name: hook\n"
                     "behaviour: wtec-rtu\n"
                     "registers:\n"
                     "  - {name: a, table: input, address: 0, access: read_write}\n"
                     "  - {name: b, address: 1, width: 3, access: read}\n"
                     "  - {name: c, address: 0xFFFF, width: 2, access: read}\n"
                     "  - {name: d, address: 2, access: write, min: 5, max: 4}\n"
                     "  - {name: e, table: coils, address: 0, width: 2, access: read}\n");
    const auto diagnostics = diagnostics_in(dir.path() / "gw.yaml", config_text("hook", "", "definitions: [devices]\n"));
    require_diagnostic(diagnostics, file, 4, 49, {"input cannot be written", "access: read"});
    require_diagnostic(diagnostics, file, 5, 34, {"3 is out of range", "1..2"});
    require_diagnostic(diagnostics, file, 6, 5, {"runs past register 0xFFFF"});
    require_diagnostic(diagnostics, file, 7, 55, {"max 4 is below min 5"});
    require_diagnostic(diagnostics, file, 8, 48, {"one bit wide"});
}
