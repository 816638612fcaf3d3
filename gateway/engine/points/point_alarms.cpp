#include "engine/points/point_alarms.hpp"

#include <cmath>
#include <optional>
#include <string_view>
#include <utility>

#include "engine/points/point_codec.hpp"

namespace fieldbridge::engine::points {

namespace {

using core::AlarmCondition;

/// The number an alarm compares: an enum's code, a bool's 0 / 1, the engineering value.
[[nodiscard]] std::optional<double> compared(const core::PointDef& point, std::span<const std::uint16_t> registers) {
    if (point.format == core::PointFormat::hex) {
        // Shown as a text, compared as the integer it is.
        const std::optional<std::int64_t> raw = raw_integer(point, registers);
        return raw ? std::optional<double>{static_cast<double>(*raw)} : std::nullopt;
    }
    const PointValue value = decode(point, registers);
    if (const auto* b = std::get_if<bool>(&value)) return *b ? 1.0 : 0.0;
    if (const auto* i = std::get_if<std::int64_t>(&value)) return static_cast<double>(*i);
    if (const auto* d = std::get_if<double>(&value); d != nullptr && !std::isnan(*d)) return *d;
    return std::nullopt;
}

[[nodiscard]] std::string threshold_text(const core::AlarmRule& rule, const core::PointDef& point) {
    if (const std::string_view label = label_of(point, static_cast<std::int64_t>(rule.threshold));
        !label.empty() && std::trunc(rule.threshold) == rule.threshold) {
        return std::string{label};
    }
    const std::string number = to_text(rule.threshold);
    return point.unit.empty() ? number : number + " " + point.unit;
}

/// The value as the JSON state shows it, as plain text.
[[nodiscard]] std::string shown_text(const core::PointDef& point, std::span<const std::uint16_t> registers) {
    PointValue value = decode(point, registers);
    if (const auto* code = std::get_if<std::int64_t>(&value); code != nullptr && !point.labels.empty()) {
        if (std::string label = enum_text(point, *code); !label.empty()) return label;
    }
    if (auto* text = std::get_if<std::string>(&value)) return std::move(*text);
    return to_text(value);
}

}  // namespace

std::string alarm_source(const core::AlarmRule& rule) {
    return rule.source.empty() ? "point " + rule.point : rule.source;
}

bool alarm_raised(const core::AlarmRule& rule, const core::PointDef& point, std::span<const std::uint16_t> registers,
                  bool was_raised) {
    if (rule.condition == AlarmCondition::bit) {
        const std::optional<std::int64_t> raw = raw_integer(point, registers);
        return raw && rule.bit < 64 && ((static_cast<std::uint64_t>(*raw) >> rule.bit) & 1U) != 0;
    }
    const std::optional<double> v = compared(point, registers);
    if (!v) {
        return false;
    }
    switch (rule.condition) {
        case AlarmCondition::above:
            return was_raised ? *v > rule.threshold - rule.hysteresis : *v > rule.threshold;
        case AlarmCondition::below:
            return was_raised ? *v < rule.threshold + rule.hysteresis : *v < rule.threshold;
        case AlarmCondition::equals: return *v == rule.threshold;
        case AlarmCondition::not_equals: return *v != rule.threshold;
        case AlarmCondition::bit: break;
    }
    return false;
}

std::string alarm_text(const core::AlarmRule& rule, const core::PointDef& point,
                       std::span<const std::uint16_t> registers) {
    if (!rule.text.empty()) {
        const std::string_view placeholder = core::AlarmRule::value_placeholder;
        std::string text;
        std::string_view rest = rule.text;
        for (std::size_t at = rest.find(placeholder); at != std::string_view::npos; at = rest.find(placeholder)) {
            text.append(rest.substr(0, at)).append(shown_text(point, registers));
            rest.remove_prefix(at + placeholder.size());
        }
        return text.append(rest);
    }
    switch (rule.condition) {
        case AlarmCondition::above: return point.name + " above " + threshold_text(rule, point);
        case AlarmCondition::below: return point.name + " below " + threshold_text(rule, point);
        case AlarmCondition::equals: return point.name + " is " + threshold_text(rule, point);
        case AlarmCondition::not_equals: return point.name + " is not " + threshold_text(rule, point);
        case AlarmCondition::bit: return "bit " + std::to_string(rule.bit) + " of " + point.name + " set";
    }
    return rule.name;
}

}  // namespace fieldbridge::engine::points
