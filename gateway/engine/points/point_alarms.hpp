#pragma once
/// @file point_alarms.hpp
/// Alarms on points (core::AlarmRule): whether a rule holds for a point's registers,
/// with hysteresis, and the text an operator reads. Pure functions: the memory of
/// which alarms are raised is the caller's (GenericProfile keeps it per device).

#include <cstdint>
#include <span>
#include <string>

#include "core/point.hpp"

namespace fieldbridge::engine::points {

/// Whether @p rule on @p point is raised now, given its registers and whether it was
/// raised at the last evaluation. above: raised when the value is above the threshold,
/// cleared once it is at or below threshold - hysteresis; below: the mirror image;
/// equals / not_equals: while the value (an enum's code, a bool's 0 / 1) equals / does
/// not equal the threshold; bit: while that bit of the raw integer is 1. A value that
/// cannot be compared (a string, NaN) raises nothing.
[[nodiscard]] bool alarm_raised(const core::AlarmRule& rule, const core::PointDef& point,
                                std::span<const std::uint16_t> registers, bool was_raised);

/// The rule's text with each `{value}` replaced by the point's value as the state shows
/// it (an enum's label, a text without quotes: "the controller reports alarm code 7"),
/// or, without a text, one naming the point, the condition and the threshold
/// ("temperature above 80 °C", "bit 3 of status set").
[[nodiscard]] std::string alarm_text(const core::AlarmRule& rule, const core::PointDef& point,
                                     std::span<const std::uint16_t> registers);

/// What the alarm names as its source: the rule's `source`, else "point <name>".
[[nodiscard]] std::string alarm_source(const core::AlarmRule& rule);

}  // namespace fieldbridge::engine::points
