// Step 1 of loading for points: `points:` and `alarms:` (of a device or of a device
// definition) and the root of a definition file -> raw values with positions.
#include "config/raw_parse.hpp"
#include "config/scalars.hpp"

namespace fieldbridge::config {

namespace {

[[nodiscard]] Field<double> read_number(const MapReader& map, std::string_view key) {
    return read_scalar<double>(map.child(key), map.sink(), "a number", parse_number);
}

RawEnum parse_enum(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref, sink);  // keys are raw values
    RawEnum raw;
    map.fill(raw);
    for (const auto& entry : map.entries()) {
        Field<std::int64_t> value;
        value.path = entry.value.path;
        value.mark = entry.key_mark;
        if (auto parsed = parse_integer(entry.key)) {
            value.value = *parsed.value;
        } else {
            value.invalid = true;
            sink.error(value, "the key '" + entry.key + "' is not an integer; enum keys are the raw values, e.g. 0: off");
        }
        Field<std::string> label = read_scalar<std::string>(
            entry.value, sink, "a label", [](std::string_view text) { return Parsed<std::string>::ok(std::string(text)); });
        raw.entries.emplace_back(std::move(value), std::move(label));
    }
    return raw;
}

/// `format:` is number, hex, or a template of the registers ("V{0}.{1}"): any other
/// text is a template, which check_point() requires to name a register.
void read_format(const MapReader& map, RawPoint& raw) {
    raw.format_text = read_string(map, "format");
    raw.format.path = raw.format_text.path;
    raw.format.mark = raw.format_text.mark;
    raw.format.invalid = raw.format_text.invalid;
    if (!raw.format_text.has_value()) return;
    for (const auto& [name, value] : core::point_format_names) {
        if (*raw.format_text == name) {
            raw.format.value = value;
            raw.format_text.value.reset();
            return;
        }
    }
    raw.format.value = core::PointFormat::text;
}

RawPoint parse_point(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref,
                        {"name", "table", "address", "type", "bit", "count", "word_order", "byte_order", "scale",
                         "offset", "unit", "enum", "enum_other", "enum_code", "writable", "min", "max", "period", "deadband",
                         "invert", "format"},
                        sink);
    RawPoint raw;
    map.fill(raw);
    raw.name = read_string(map, "name");
    raw.table = read_enum(map, "table", core::register_table_names);
    raw.address = read_int(map, "address");
    raw.type = read_enum(map, "type", core::point_type_names);
    raw.bit = read_int(map, "bit");
    raw.count = read_int(map, "count");
    raw.word_order = read_enum(map, "word_order", core::word_order_names);
    raw.byte_order = read_enum(map, "byte_order", core::byte_order_names);
    raw.scale = read_number(map, "scale");
    raw.offset = read_number(map, "offset");
    raw.unit = read_string(map, "unit");
    raw.labels = parse_enum(map.child("enum"), sink);
    raw.enum_other = read_string(map, "enum_other");
    raw.enum_code = read_bool(map, "enum_code");
    raw.writable = read_bool(map, "writable");
    raw.min = read_number(map, "min");
    raw.max = read_number(map, "max");
    raw.period = read_duration(map, "period");
    raw.deadband = read_number(map, "deadband");
    raw.invert = read_bool(map, "invert");
    read_format(map, raw);
    return raw;
}

RawAlarm parse_alarm(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref,
                        {"name", "point", "above", "below", "equals", "not_equals", "bit", "hysteresis", "severity",
                         "text", "source"},
                        sink);
    RawAlarm raw;
    map.fill(raw);
    raw.name = read_string(map, "name");
    raw.point = read_string(map, "point");
    raw.above = read_number(map, "above");
    raw.below = read_number(map, "below");
    raw.equals = read_string(map, "equals");
    raw.not_equals = read_string(map, "not_equals");
    raw.bit = read_int(map, "bit");
    raw.hysteresis = read_number(map, "hysteresis");
    raw.severity = read_enum(map, "severity", core::alarm_severity_names);
    raw.text = read_string(map, "text");
    raw.source = read_string(map, "source");
    return raw;
}

RawIdentify parse_identify(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref, {"table", "address", "count", "expect"}, sink);
    RawIdentify raw;
    map.fill(raw);
    raw.table = read_enum(map, "table", core::register_table_names);
    raw.address = read_int(map, "address");
    raw.count = read_int(map, "count");
    raw.expect = read_list<std::int64_t>(map, "expect", "register values", parse_integer);
    return raw;
}

RawRegister parse_register(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref,
                        {"name", "table", "address", "width", "count", "access", "min", "max", "motion", "protected",
                         "auto_reset", "stop"},
                        sink);
    RawRegister raw;
    map.fill(raw);
    raw.name = read_string(map, "name");
    raw.table = read_enum(map, "table", core::register_table_names);
    raw.address = read_int(map, "address");
    raw.width = read_int(map, "width");
    raw.count = read_int(map, "count");
    raw.access = read_enum(map, "access", core::access_names);
    raw.min = read_int(map, "min");
    raw.max = read_int(map, "max");
    raw.motion = read_bool(map, "motion");
    raw.protect = read_bool(map, "protected");
    raw.auto_reset = read_bool(map, "auto_reset");
    raw.stop = read_int(map, "stop");
    return raw;
}

}  // namespace

RawSeq<RawPoint> parse_points(const MapReader& map, std::string_view key) {
    return read_seq<RawPoint>(map, key, parse_point);
}

RawSeq<RawAlarm> parse_alarms(const MapReader& map, std::string_view key) {
    return read_seq<RawAlarm>(map, key, parse_alarm);
}

RawDefinition parse_definition(const YAML::Node& root, std::string file, DiagnosticSink& sink) {
    const NodeRef root_ref{root, "", to_mark(root.Mark(), Mark{1, 1})};
    const MapReader map(root_ref,
                        {"name", "description", "word_order", "period", "max_gap", "points", "alarms", "blocks",
                         "identify", "behaviour", "registers"},
                        sink, true);
    RawDefinition raw;
    map.fill(raw);
    raw.file = std::move(file);
    raw.name = read_string(map, "name");
    raw.description = read_string(map, "description");
    raw.word_order = read_enum(map, "word_order", core::word_order_names);
    raw.period = read_duration(map, "period");
    raw.max_gap = read_int(map, "max_gap");
    raw.points = parse_points(map, "points");
    raw.alarms = parse_alarms(map, "alarms");
    raw.blocks = read_seq<RawBlock>(map, "blocks", parse_block);
    raw.identify = parse_identify(map.child("identify"), sink);
    raw.behaviour = read_enum(map, "behaviour", core::behaviour_names);
    raw.registers = read_seq<RawRegister>(map, "registers", parse_register);
    return raw;
}

}  // namespace fieldbridge::config
