#pragma once
/// @file point.hpp
/// The point model (docs/devices.md): a device's values as named, typed points over
/// its Modbus tables, and the alarms raised from them. Filled by the configuration
/// (inline `points:` or a device definition file), read by the engine (poll plan,
/// decoding, write checks), MQTT (fields, `write` / `read` ops) and the simulator.
/// Plain data: every default is already applied when a PointDef leaves the config.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/names.hpp"
#include "core/register_table.hpp"
#include "core/word_order.hpp"

namespace fieldbridge::core {

/// The value type of a point. `boolean` is spelled `bool` in files.
enum class PointType : std::uint8_t {
    boolean,
    int16,
    uint16,
    int32,
    uint32,
    int64,
    uint64,
    float32,
    float64,
    string,
};

inline constexpr NameTable<PointType, 10> point_type_names{{
    {"bool", PointType::boolean},
    {"int16", PointType::int16},
    {"uint16", PointType::uint16},
    {"int32", PointType::int32},
    {"uint32", PointType::uint32},
    {"int64", PointType::int64},
    {"uint64", PointType::uint64},
    {"float32", PointType::float32},
    {"float64", PointType::float64},
    {"string", PointType::string},
}};
template <>
struct Names<PointType> {
    static constexpr const auto& table = point_type_names;
};

/// Registers a value of @p type takes (string: its `count`; bool: 1).
[[nodiscard]] constexpr std::uint16_t registers_of(PointType type, std::uint16_t string_count = 0) noexcept {
    switch (type) {
        case PointType::boolean:
        case PointType::int16:
        case PointType::uint16: return 1;
        case PointType::int32:
        case PointType::uint32:
        case PointType::float32: return 2;
        case PointType::int64:
        case PointType::uint64:
        case PointType::float64: return 4;
        case PointType::string: return string_count;
    }
    return 1;
}

/// Byte order inside each register of a multi-register value (and of a string).
enum class ByteOrder : std::uint8_t { big, little };

inline constexpr NameTable<ByteOrder, 2> byte_order_names{{
    {"big", ByteOrder::big},
    {"little", ByteOrder::little},
}};
template <>
struct Names<ByteOrder> {
    static constexpr const auto& table = byte_order_names;
};

/// How an integer point's value is shown (`format:`): a number, or its registers as
/// one hexadecimal text, "0x" and four upper-case digits per register ("0x00000078"
/// for a uint32), for identifiers and versions that are codes rather than amounts;
/// or `text`: its `count` registers through a template (PointDef::format_text,
/// core/text_template.hpp), written in files as the template itself ("V{0}.{1}").
enum class PointFormat : std::uint8_t { number, hex, text };

inline constexpr NameTable<PointFormat, 2> point_format_names{{
    {"number", PointFormat::number},
    {"hex", PointFormat::hex},
}};
template <>
struct Names<PointFormat> {
    static constexpr const auto& table = point_format_names;
};

/// One label of an enumerated point: raw value -> label.
struct EnumLabel {
    std::int64_t value = 0;
    std::string label;
    bool operator==(const EnumLabel&) const = default;
};

struct PointDef {
    std::string name;  ///< snake_case, unique in the device
    RegisterTable table = RegisterTable::holding;
    std::uint16_t address = 0;
    PointType type = PointType::uint16;
    std::optional<std::uint8_t> bit;  ///< 0-15: a bool of one bit of a register
    std::uint16_t count = 0;          ///< string: registers (two characters each); format text: registers
    WordOrder word_order = WordOrder::high_first;
    ByteOrder byte_order = ByteOrder::big;
    double scale = 1.0;  ///< engineering value = raw × scale + offset
    double offset = 0.0;
    std::string unit;
    std::vector<EnumLabel> labels;  ///< `enum:`; empty when none
    std::string enum_other;         ///< the label of a code `enum:` does not name; empty: the code itself
    bool enum_code = true;          ///< an enum point also gives `<name>_code`
    bool writable = false;
    std::optional<double> min;  ///< writes, engineering units
    std::optional<double> max;
    std::chrono::milliseconds period{1000};
    std::optional<double> deadband;  ///< MQTT, engineering units
    bool invert = false;                        ///< bool points: true while the bit (coil) is 0
    PointFormat format = PointFormat::number;  ///< integer points: `hex` and `text` show a text
    std::string format_text;                   ///< `text`: the template; `{0}`... are its registers

    /// The name by which `enum_other` shows the code it stands for: `{value}`, `{value:hex}`.
    static constexpr std::string_view code_placeholder = "value";

    /// Registers (or bits) the point spans.
    [[nodiscard]] std::uint16_t width() const noexcept {
        if (is_bit_table(table)) return 1;
        return format == PointFormat::text ? count : registers_of(type, count);
    }
    /// True when the point is one bit of a coil / discrete input or of a register.
    [[nodiscard]] bool is_bool() const noexcept { return type == PointType::boolean; }
    bool operator==(const PointDef&) const = default;
};

enum class AlarmCondition : std::uint8_t { above, below, equals, not_equals, bit };

inline constexpr NameTable<AlarmCondition, 5> alarm_condition_names{{
    {"above", AlarmCondition::above},
    {"below", AlarmCondition::below},
    {"equals", AlarmCondition::equals},
    {"not_equals", AlarmCondition::not_equals},
    {"bit", AlarmCondition::bit},
}};
template <>
struct Names<AlarmCondition> {
    static constexpr const auto& table = alarm_condition_names;
};

enum class AlarmSeverity : std::uint8_t { warning, error, critical };

inline constexpr NameTable<AlarmSeverity, 3> alarm_severity_names{{
    {"warning", AlarmSeverity::warning},
    {"error", AlarmSeverity::error},
    {"critical", AlarmSeverity::critical},
}};
template <>
struct Names<AlarmSeverity> {
    static constexpr const auto& table = alarm_severity_names;
};

/// An alarm on a point: raised while the condition holds, cleared when it no longer
/// holds by `hysteresis` (above: value <= threshold - hysteresis; below: value >=
/// threshold + hysteresis; equals / not_equals / bit: as soon as it no longer holds).
struct AlarmRule {
    /// Where `text` shows the point's value (as the state shows it) at the time.
    static constexpr std::string_view value_placeholder = "{value}";
    std::string name;   ///< the alarm's code on MQTT
    std::string point;  ///< a point of the device
    AlarmCondition condition = AlarmCondition::above;
    double threshold = 0;  ///< above / below / equals / not_equals: engineering units or enum code
    std::uint8_t bit = 0;  ///< condition `bit`: raised while this bit of the raw value is 1
    double hysteresis = 0;
    AlarmSeverity severity = AlarmSeverity::warning;
    std::string text;    ///< for operators, `{value}` replaced by the point's value; when empty, made from the rule
    std::string source;  ///< what the alarm names as its source; "point <point>" when empty
    bool operator==(const AlarmRule&) const = default;
};

/// The optional read `fieldbridge scan` sends to recognise a device of a definition:
/// FC03 / FC04 of `count` registers from `address`; it matches when the reply's
/// registers equal `expect` (when given) or when the device answers at all.
struct IdentifyRead {
    RegisterTable table = RegisterTable::holding;
    std::uint16_t address = 0;
    std::uint16_t count = 1;
    std::vector<std::uint16_t> expect;
    bool operator==(const IdentifyRead&) const = default;
};

/// Everything points make of a device: its points and alarms (definition file and
/// inline ones together), and how its reads are merged.
struct PointModel {
    std::vector<PointDef> points;
    std::vector<AlarmRule> alarms;
    /// Registers (bits) that no point names which a merged read may bridge.
    static constexpr std::uint16_t default_max_gap = 8;
    std::uint16_t max_gap = default_max_gap;
    bool operator==(const PointModel&) const = default;
};

}  // namespace fieldbridge::core
