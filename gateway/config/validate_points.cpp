// Step 2 of loading for points and their alarms (docs/devices.md): each point's
// keys, names unique in the device, no overlap of different values on one register,
// and alarms that name a point they can be evaluated on.
#include <algorithm>
#include <cmath>

#include "config/validate.hpp"
#include "core/text_template.hpp"

namespace fieldbridge::config {

namespace {

using core::PointType;

[[nodiscard]] std::string type_text(PointType type) { return std::string(core::to_string(type)); }

[[nodiscard]] bool is_integer(PointType type) noexcept {
    return type != PointType::boolean && type != PointType::float32 && type != PointType::float64 &&
           type != PointType::string;
}

[[nodiscard]] bool is_numeric(PointType type) noexcept {
    return type != PointType::boolean && type != PointType::string;
}

/// Reports a key that the point's type does not have.
template <class T>
void refuse_for_type(DiagnosticSink& sink, const Field<T>& field, std::string_view key, PointType type,
                     std::string_view applies_to) {
    if (field.has_value()) {
        sink.error(field, std::string(key) + " applies only to " + std::string(applies_to) + " (this point is " +
                              type_text(type) + "); remove it");
    }
}

[[nodiscard]] bool is_text_format(const RawPoint& point) noexcept {
    return point.format.has_value() && *point.format == core::PointFormat::text;
}

/// Registers (bits) the point spans, its shape being valid.
[[nodiscard]] std::int64_t width_of(const RawPoint& point, PointType type) {
    if (point.table.has_value() && core::is_bit_table(*point.table)) return 1;
    const auto count = static_cast<std::uint16_t>(point.count.value_or(0));
    return is_text_format(point) ? count : core::registers_of(type, count);
}

/// `enum_other:` may show the code as {value} or {value:hex}.
void check_enum_other(const RawPoint& point, DiagnosticSink& sink) {
    if (!point.enum_other.has_value()) return;
    const auto error = core::template_error(
        *point.enum_other, [](std::string_view name) { return name == core::PointDef::code_placeholder; });
    if (error) {
        sink.error(point.enum_other, *error + "; enum_other may show the code as {value} or {value:hex} (write "
                                              "{{ and }} for braces)");
    }
}

/// A point shown as a text (`format: hex`, a template) shows its registers as they
/// are: nothing to scale or label. @p format names the format in the messages.
void refuse_number_keys(const RawPoint& point, std::string_view format, DiagnosticSink& sink) {
    const std::string with = "a point with " + std::string(format);
    for (const auto* key : {&point.scale, &point.offset, &point.min, &point.max, &point.deadband}) {
        if (key->has_value()) {
            sink.error(*key, with + " shows its registers as a text; remove this key (or the format)");
        }
    }
    if (!point.labels.absent()) {
        sink.error(point.labels, with + " shows its registers as a text, not a label; remove enum (or the format)");
    }
}

/// `format:` as a template ("V{0}.{1}.{2}.{3}"): `count` registers of int16 / uint16,
/// each placeholder one of them, read-only and unscaled.
void check_text_format(const RawPoint& point, PointType type, DiagnosticSink& sink) {
    if (type != PointType::uint16 && type != PointType::int16) {
        sink.error(point.format, "'" + *point.format_text + "' is neither number nor hex, so it is a template of "
                                 "registers, which applies to uint16 and int16 points (this point is " +
                                 type_text(type) + "); expected number, hex or type: uint16");
        return;
    }
    const std::int64_t count = point.count.value_or(0);
    std::optional<std::string> error = core::template_error(*point.format_text, [count](std::string_view name) {
        std::int64_t index = 0;
        for (const char c : name) {
            if (c < '0' || c > '9' || index > 1000) return false;
            index = index * 10 + (c - '0');
        }
        return index < count;
    });
    if (!error && !core::has_placeholder(*point.format_text)) {
        error = "it names no register";
    }
    if (error) {
        sink.error(point.format, "format '" + *point.format_text + "': " + *error +
                                     "; expected number, hex, or a template of the point's count: registers, {0} "
                                     "to {" + std::to_string(count > 0 ? count - 1 : 0) +
                                     "} ({0:hex}: 0x and four digits)");
    }
    refuse_number_keys(point, "a format template", sink);
    if (point.writable.value_or(false)) {
        sink.error(point.writable, "a point with a format template is read-only; expected writable: false");
    }
}

void check_labels(const RawPoint& point, PointType type, DiagnosticSink& sink) {
    if (point.labels.absent()) {
        if (point.enum_code.has_value()) {
            sink.error(point.enum_code, "enum_code applies only to a point with enum; remove it");
        }
        if (point.enum_other.has_value()) {
            sink.error(point.enum_other, "enum_other applies only to a point with enum; remove it");
        }
        return;
    }
    if (!point.labels.ok()) {
        return;
    }
    if (point.enum_other.has_value() && point.enum_other->empty()) {
        sink.error(point.enum_other, "the label is empty; expected a text such as 'unknown' (or remove enum_other: "
                                     "the code then stands for itself)");
    }
    check_enum_other(point, sink);
    // Writes name values by label: a writable point needs one value per label. A
    // read-only one may show several codes alike (two spellings of one state).
    const bool writable = point.writable.value_or(false);
    if (writable && point.enum_code.has_value() && !*point.enum_code) {
        sink.error(point.enum_code, "a writable enum point keeps its <name>_code (Sparkplug B writes the code); "
                                    "remove enum_code: false or writable");
    }
    if (!is_integer(type) && type != PointType::boolean) {
        sink.error(point.labels, "enum applies only to integer and bool points (this point is " + type_text(type) +
                                     "); remove it or change the type");
        return;
    }
    if (point.labels.entries.empty()) {
        sink.error(point.labels, "is empty; expected raw value: label pairs, e.g. {0: off, 1: heat}");
    }
    for (std::size_t i = 0; i < point.labels.entries.size(); ++i) {
        const auto& [value, label] = point.labels.entries[i];
        if (label.has_value() && label->empty()) {
            sink.error(label, "the label is empty; expected a text such as 'heat'");
        }
        for (std::size_t j = 0; j < i; ++j) {
            const auto& [other_value, other_label] = point.labels.entries[j];
            if (value.has_value() && other_value.has_value() && *value == *other_value) {
                sink.error(value, "the raw value " + std::to_string(*value) + " is already labelled '" +
                                      other_label.value_or("") + "'; expected one label per value");
            } else if (writable && label.has_value() && other_label.has_value() && *label == *other_label) {
                sink.error(label, "the label '" + *label + "' is already used for " +
                                      std::to_string(other_value.value_or(0)) +
                                      "; expected one value per label on a writable point (writes name values "
                                      "by label)");
            }
        }
    }
}

/// The keys of one point that do not depend on the other points.
/// Returns true when its table, address and width are known and valid.
bool check_point(const RawPoint& point, DiagnosticSink& sink) {
    if (require(sink, point.name, "a snake_case name such as supply_voltage")) {
        check_point_name(sink, point.name);
    }
    require(sink, point.table, "one of coils, discrete_inputs, holding, input");
    const bool has_address = require(sink, point.address, "the register (or coil) address, e.g. 0x0010") &&
                             check_range(sink, point.address, Range<std::int64_t>{0, 0xFFFF});
    if (point.type.invalid || point.bit.invalid || point.table.invalid) {
        return false;  // reported; the rest depends on them
    }
    const PointType type = effective_type(point);
    bool shape_ok = point.table.has_value() && has_address;
    const bool bits = point.table.has_value() && core::is_bit_table(*point.table);
    if (point.bit.has_value()) {
        if (!check_range(sink, point.bit, Range<std::int64_t>{0, 15})) {
            shape_ok = false;
        } else if (bits) {
            sink.error(point.bit, "bit applies to holding and input registers (a coil or discrete input is "
                                  "already one bit); remove it");
            shape_ok = false;
        } else if (type != PointType::boolean) {
            sink.error(point.type, "a point with bit: is a bool; expected type: bool (or remove type)");
            shape_ok = false;
        }
    } else if (bits && type != PointType::boolean) {
        sink.error(point.type, "table " + std::string(core::to_string(*point.table)) +
                                   " holds single bits; expected type: bool (or remove type)");
        shape_ok = false;
    }
    // A bool of a holding / input register without bit: is the whole register, true
    // while it is not 0 (a flag register that reads 0 / 1).
    if (is_text_format(point) && !bits && !point.bit.has_value() && core::has_placeholder(*point.format_text)) {
        if (require(sink, point.count, "the number of registers the format template shows, 1..125")) {
            shape_ok = check_range(sink, point.count, Range<std::int64_t>{1, RegisterBlock::max_registers}) && shape_ok;
        } else {
            shape_ok = false;
        }
    } else if (type == PointType::string && !bits) {
        if (require(sink, point.count, "the number of registers of the string (two characters each), 1..125")) {
            shape_ok = check_range(sink, point.count, Range<std::int64_t>{1, RegisterBlock::max_registers}) && shape_ok;
        } else {
            shape_ok = false;
        }
    } else if (point.count.has_value()) {
        sink.error(point.count, "count applies only to string points; a " + type_text(type) + " takes " +
                                    std::to_string(core::registers_of(type)) + " register(s); remove it");
    }
    if (shape_ok) {
        const std::int64_t width = width_of(point, type);
        if (*point.address + width - 1 > 0xFFFF) {
            sink.error(point.address, "the point " + hex16(*point.address) + " + " + std::to_string(width) +
                                          " registers runs past 0xFFFF; expected address + width - 1 <= 0xFFFF");
            shape_ok = false;
        }
    }
    if (point.scale.has_value() && is_numeric(type) && *point.scale == 0) {
        sink.error(point.scale, "scale 0 would make every value 0; expected a non-zero factor (1 when absent)");
    }
    if (!is_numeric(type)) {
        refuse_for_type(sink, point.scale, "scale", type, "numeric points");
        refuse_for_type(sink, point.offset, "offset", type, "numeric points");
        refuse_for_type(sink, point.min, "min", type, "numeric points");
        refuse_for_type(sink, point.max, "max", type, "numeric points");
        refuse_for_type(sink, point.deadband, "deadband", type, "numeric points");
    }
    check_labels(point, type, sink);
    if (point.invert.has_value() && type != PointType::boolean) {
        sink.error(point.invert, "invert applies only to bool points (this point is " + type_text(type) +
                                     "); remove it");
    }
    if (is_text_format(point)) {
        if (bits || point.bit.has_value()) {
            sink.error(point.format, "a format template shows registers; a bit is a bool (expected number, or "
                                     "remove format)");
        } else {
            check_text_format(point, type, sink);
        }
    }
    if (point.format.has_value() && *point.format == core::PointFormat::hex) {
        if (!is_integer(type)) {
            sink.error(point.format, "format: hex applies only to integer points (this point is " + type_text(type) +
                                         "); remove it");
        } else {
            refuse_number_keys(point, "format: hex", sink);
            if (point.writable.value_or(false)) {
                sink.error(point.writable, "a point with format: hex is read-only; expected writable: false (or "
                                           "remove the format to write it as a number)");
            }
        }
    }
    if (point.writable.value_or(false) && point.table.has_value() &&
        (*point.table == RegisterTable::input || *point.table == RegisterTable::discrete_inputs)) {
        sink.error(point.writable, "table " + std::string(core::to_string(*point.table)) +
                                       " is read-only in Modbus; expected writable: false (or table: " +
                                       (*point.table == RegisterTable::input ? "holding" : "coils") + ")");
    }
    if (point.min.has_value() && point.max.has_value() && *point.max < *point.min) {
        sink.error(point.max, "max (" + format_number(*point.max) + ") is below min (" + format_number(*point.min) +
                                  "); expected min <= max");
    }
    if (point.deadband.has_value() && *point.deadband < 0) {
        sink.error(point.deadband, "a deadband is a change size; expected a number >= 0");
    }
    check_range(sink, point.period, RegisterBlock::period_range);
    return shape_ok;
}

/// `text:` may name the point's value as {value}; any other brace is a typo. `source:`
/// is one line for operators.
void check_alarm_text(const RawAlarm& alarm, DiagnosticSink& sink) {
    if (alarm.text.has_value()) {
        std::string_view rest = *alarm.text;
        for (std::size_t at = rest.find_first_of("{}"); at != std::string_view::npos; at = rest.find_first_of("{}")) {
            if (rest.substr(at).starts_with(core::AlarmRule::value_placeholder)) {
                rest.remove_prefix(at + core::AlarmRule::value_placeholder.size());
                continue;
            }
            sink.error(alarm.text, "the text has a brace that is not {value}; expected {value} (the point's value "
                                   "when the alarm is raised) or no braces");
            break;
        }
    }
    if (alarm.source.has_value() &&
        (alarm.source->empty() || alarm.source->size() > 128 ||
         std::any_of(alarm.source->begin(), alarm.source->end(), [](char c) { return c < 0x20 || c == 0x7F; }))) {
        sink.error(alarm.source, "expected one line of up to 128 characters naming where the alarm comes from, "
                                 "e.g. holding 0x02D6 (without source: the point's name)");
    }
}

[[nodiscard]] std::string where_of(const PointSpan& span) {
    return span.path + " (" + span.file + ":" + std::to_string(span.line) + ")";
}

/// Two points on common registers must read them the same way; bit points may
/// share a register with each other.
void check_overlap(const PointSpan& point, const PointSpan& other, DiagnosticSink& sink) {
    if (!point.shape_ok || !other.shape_ok || point.table != other.table || point.last < other.first ||
        other.last < point.first) {
        return;
    }
    const bool both_bits = point.bit && other.bit;
    const bool identical = !point.bit && !other.bit && point.first == other.first && point.last == other.last &&
                           point.type == other.type;
    if (both_bits || identical) {
        return;
    }
    const auto describe = [](const PointSpan& s) {
        return "'" + s.name + "' (" + std::string(s.bit ? "bool of a bit" : type_text(s.type)) + ", " +
               hex16(s.first) + (s.last != s.first ? "-" + hex16(s.last) : "") + ")";
    };
    sink.error(point.raw->mark, point.path,
               describe(point) + " overlaps " + describe(other) + " of " + where_of(other) + " in table " +
                   std::string(core::to_string(point.table)) +
                   "; points on common registers must have the same type and width (or all be bit: points)");
}

}  // namespace

bool is_point_name(std::string_view name) noexcept {
    if (name.empty() || name.size() > max_name_length || name.front() < 'a' || name.front() > 'z') {
        return false;
    }
    return std::all_of(name.begin(), name.end(),
                       [](char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_'; });
}

bool check_point_name(DiagnosticSink& sink, const Field<std::string>& field) {
    if (!field.has_value()) {
        return false;
    }
    if (!is_point_name(*field)) {
        sink.error(field, "'" + *field + "' is not a snake_case name; expected 1.." + std::to_string(max_name_length) +
                              " characters from a-z 0-9 _, starting with a letter (it becomes a JSON field)");
        return false;
    }
    return true;
}

core::PointType effective_type(const RawPoint& point) noexcept {
    if (point.type.has_value()) {
        return *point.type;
    }
    const bool bits = point.table.has_value() && core::is_bit_table(*point.table);
    return bits || point.bit.has_value() ? PointType::boolean : PointType::uint16;
}

std::vector<PointSpan> check_points(const RawSeq<RawPoint>& points, std::vector<PointSpan> earlier,
                                    DiagnosticSink& sink) {
    for (const RawPoint& point : points.items) {
        if (!point.ok()) {
            continue;
        }
        const bool shape_ok = check_point(point, sink);
        if (!point.name.has_value()) {
            continue;
        }
        PointSpan span;
        span.name = *point.name;
        span.path = point.path;
        span.file = sink.file();
        span.line = point.mark.line;
        span.raw = &point;
        span.type = effective_type(point);
        span.text = is_text_format(point);
        span.shape_ok = shape_ok;
        if (shape_ok) {
            span.table = *point.table;
            span.bit = point.bit.has_value();
            span.first = *point.address;
            span.last = span.first + width_of(point, span.type) - 1;
        }
        const auto same_name =
            std::find_if(earlier.begin(), earlier.end(), [&](const PointSpan& s) { return s.name == span.name; });
        if (same_name != earlier.end()) {
            sink.error(point.name, "the point name '" + span.name + "' is already used by " + where_of(*same_name) +
                                       "; expected names unique in the device");
        } else {
            for (const auto& other : earlier) {
                check_overlap(span, other, sink);
            }
        }
        earlier.push_back(std::move(span));
    }
    return earlier;
}

std::optional<double> alarm_value(const Field<std::string>& field, const RawPoint& point) {
    if (!field.has_value()) {
        return std::nullopt;
    }
    if (auto number = parse_number(*field)) {
        return *number.value;
    }
    for (const auto& [value, label] : point.labels.entries) {
        if (label.has_value() && value.has_value() && *label == *field) {
            return static_cast<double>(*value);
        }
    }
    return std::nullopt;
}

std::vector<std::string> check_alarms(const RawSeq<RawAlarm>& alarms, const std::vector<PointSpan>& points,
                                      std::vector<std::string> earlier, DiagnosticSink& sink) {
    for (const RawAlarm& alarm : alarms.items) {
        if (!alarm.ok()) {
            continue;
        }
        if (require(sink, alarm.name, "a snake_case name such as over_temperature") &&
            check_point_name(sink, alarm.name)) {
            if (std::find(earlier.begin(), earlier.end(), *alarm.name) != earlier.end()) {
                sink.error(alarm.name, "the alarm name '" + *alarm.name +
                                           "' is already used in this device; expected names unique in the device");
            }
            earlier.push_back(*alarm.name);
        }
        const int conditions = int{alarm.above.has_value()} + int{alarm.below.has_value()} +
                               int{alarm.equals.has_value()} + int{alarm.not_equals.has_value()} +
                               int{alarm.bit.has_value()};
        if (conditions != 1 && !alarm.above.invalid && !alarm.below.invalid && !alarm.bit.invalid) {
            sink.error(alarm, std::string(conditions == 0 ? "has no condition" : "has several conditions") +
                                  "; expected exactly one of above, below, equals, not_equals, bit");
        }
        check_range(sink, alarm.bit, Range<std::int64_t>{0, 63});
        check_alarm_text(alarm, sink);
        if (alarm.hysteresis.has_value() && *alarm.hysteresis < 0) {
            sink.error(alarm.hysteresis, "expected a number >= 0 (how far back past the threshold clears it)");
        }
        if (!require(sink, alarm.point, "the name of a point of this device")) {
            continue;
        }
        const auto found =
            std::find_if(points.begin(), points.end(), [&](const PointSpan& s) { return s.name == *alarm.point; });
        if (found == points.end()) {
            std::string names;
            for (const auto& p : points) {
                names += (names.empty() ? "" : ", ") + p.name;
            }
            sink.error(alarm.point, "the device has no point '" + *alarm.point + "'; expected one of: " +
                                        (names.empty() ? "(no points)" : names));
            continue;
        }
        const PointType type = found->type;
        const std::string of_point =
            " (point '" + found->name + "' is " + (found->text ? "a text by its format template" : type_text(type)) + ")";
        if (found->text) {
            sink.error(alarm.point, "an alarm compares a number; the point '" + found->name +
                                        "' shows its registers as a text (its format template)");
            continue;
        }
        for (const auto* field : {&alarm.above, &alarm.below}) {
            if (field->has_value() && !is_numeric(type)) {
                sink.error(*field, "above / below compare numbers" + of_point + "; use equals or not_equals");
            }
        }
        for (const auto* field : {&alarm.equals, &alarm.not_equals}) {
            if (!field->has_value()) {
                continue;
            }
            if (type == PointType::string || found->text) {
                sink.error(*field, "equals / not_equals compare numbers or enum labels" + of_point);
            } else if (!alarm_value(*field, *found->raw)) {
                sink.error(*field, "'" + **field + "' is neither a number nor a label of the point's enum" + of_point);
            }
        }
        if (alarm.bit.has_value() && !is_integer(type)) {
            sink.error(alarm.bit, "bit applies to integer points" + of_point + "; use equals on a bool point");
        } else if (alarm.bit.has_value() && found->shape_ok && *alarm.bit >= 16 * (found->last - found->first + 1)) {
            sink.error(alarm.bit, "bit " + std::to_string(*alarm.bit) + " is beyond the " +
                                      std::to_string(16 * (found->last - found->first + 1)) + " bits" + of_point);
        }
    }
    return earlier;
}

}  // namespace fieldbridge::config
