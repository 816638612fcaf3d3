#include "engine/profiles/point_state.hpp"

#include <algorithm>
#include <string>
#include <utility>
#include <variant>

#include "engine/points/point_alarms.hpp"
#include "engine/points/point_codec.hpp"

namespace fieldbridge::engine {

namespace {

[[nodiscard]] Severity severity_of(core::AlarmSeverity s) noexcept {
    switch (s) {
        case core::AlarmSeverity::warning: return Severity::warning;
        case core::AlarmSeverity::error: return Severity::error;
        case core::AlarmSeverity::critical: return Severity::critical;
    }
    return Severity::error;
}

[[nodiscard]] FieldValue field_value(points::PointValue value) {
    return std::visit([](auto&& v) -> FieldValue { return FieldValue{std::forward<decltype(v)>(v)}; },
                      std::move(value));
}

}  // namespace

PointState::PointState(core::PointModel model) : model_(std::move(model)), raised_(model_.alarms.size(), false) {
    for (const core::AlarmRule& rule : model_.alarms) {
        const auto it = std::find_if(model_.points.begin(), model_.points.end(),
                                     [&rule](const core::PointDef& p) { return p.name == rule.point; });
        if (it == model_.points.end()) {
            throw ProfileError("the alarm '" + rule.name + "' names no point of the device ('" + rule.point +
                               "'); fix alarms: in its definition");
        }
        alarm_points_.push_back(static_cast<std::size_t>(it - model_.points.begin()));
    }
}

std::vector<std::uint16_t> PointState::registers_of(const RegisterImage& image, std::size_t index) const {
    const core::PointDef& p = model_.points[index];
    std::vector<std::uint16_t> out;
    out.reserve(p.width());
    for (std::size_t k = 0; k < p.width(); ++k) {
        const std::optional<std::uint16_t> v = image.value(p.table, static_cast<std::uint16_t>(p.address + k));
        if (!v) {
            return {};
        }
        out.push_back(*v);
    }
    return out;
}

DecodedState PointState::decode(const RegisterImage& image) const {
    DecodedState state;
    for (std::size_t i = 0; i < model_.points.size(); ++i) {
        const core::PointDef& p = model_.points[i];
        const std::vector<std::uint16_t> registers = registers_of(image, i);
        if (registers.empty()) {
            continue;
        }
        points::PointValue value = points::decode(p, registers);
        if (!p.labels.empty()) {
            if (const auto* code = std::get_if<std::int64_t>(&value)) {
                // A code the enum does not name: `enum_other`, else the code stands in.
                std::string label = points::enum_text(p, *code);
                if (!label.empty()) {
                    state.fields.push_back(Field{p.name, std::move(label), p.unit});
                } else {
                    state.fields.push_back(Field{p.name, *code, p.unit});
                }
                if (p.enum_code) state.fields.push_back(Field{p.name + "_code", *code, ""});
                continue;
            }
        }
        state.fields.push_back(Field{p.name, field_value(std::move(value)), p.unit});
    }
    return state;
}

std::vector<Alarm> PointState::alarms(const RegisterImage& image) const {
    std::vector<Alarm> out;
    const std::lock_guard lock(mutex_);
    for (std::size_t r = 0; r < model_.alarms.size(); ++r) {
        const core::AlarmRule& rule = model_.alarms[r];
        const core::PointDef& point = model_.points[alarm_points_[r]];
        const std::vector<std::uint16_t> registers = registers_of(image, alarm_points_[r]);
        raised_[r] = !registers.empty() && points::alarm_raised(rule, point, registers, raised_[r]);
        if (raised_[r]) {
            out.push_back(Alarm{rule.name, points::alarm_text(rule, point, registers), severity_of(rule.severity),
                                points::alarm_source(rule)});
        }
    }
    return out;
}

}  // namespace fieldbridge::engine
