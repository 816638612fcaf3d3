#include "northbound/mqtt/point_commands.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/log_text.hpp"
#include "engine/points/point_requests.hpp"

namespace fieldbridge::northbound::mqtt {

namespace {

using engine::points::find_point;
using nlohmann::json;

PointOp refuse(std::string kind, std::string message) {
    PointOp op;
    op.kind = std::move(kind);
    op.message = std::move(message);
    return op;
}

std::string point_name(const std::string& name) { return "point " + core::quoted(name); }

/// The JSON value as the codec takes it, or nullopt when its JSON type cannot fit the
/// point (the codec checks the value itself).
std::optional<engine::points::PointValue> value_for(const core::PointDef& point, const json& value) {
    if (point.type == core::PointType::boolean) {
        if (value.is_boolean()) return value.get<bool>();
        return std::nullopt;
    }
    if (point.type == core::PointType::string) {
        if (value.is_string()) return value.get<std::string>();
        return std::nullopt;
    }
    if (value.is_string() && !point.labels.empty()) return value.get<std::string>();  // an enum label
    if (value.is_number_integer() && !value.is_number_unsigned()) return value.get<std::int64_t>();
    if (value.is_number()) return value.get<double>();
    return std::nullopt;
}

std::string expected_type(const core::PointDef& point) {
    switch (point.type) {
        case core::PointType::boolean: return "true or false";
        case core::PointType::string: return "a string";
        default: return point.labels.empty() ? "a number" : "a number or one of its enum labels";
    }
}

}  // namespace

bool takes_point_write(const core::PointModel& points) noexcept {
    return std::any_of(points.points.begin(), points.points.end(), [](const core::PointDef& p) { return p.writable; });
}

bool takes_point_read(const core::PointModel& points) noexcept { return !points.points.empty(); }

PointOp point_write(const core::PointModel& points, const json* values) {
    if (values == nullptr) return refuse("missing_field", "field 'values' is required");
    if (!values->is_object() || values->empty()) {
        return refuse("invalid_field", "field 'values' must be an object of point names and values");
    }
    // In the order of the device's points, whatever the order in the JSON.
    std::vector<engine::points::PointWrite> writes;
    for (const auto& [name, value] : values->items()) {
        const core::PointDef* point = find_point(points, name);
        if (point == nullptr) {
            return refuse("invalid_field", point_name(name) + " is not a point of this device; nothing was written");
        }
        if (!point->writable) {
            return refuse("invalid_field", point_name(name) + " is read-only; nothing was written");
        }
        auto converted = value_for(*point, value);
        if (!converted) {
            return refuse("invalid_field",
                          point_name(name) + " takes " + expected_type(*point) + "; nothing was written");
        }
        writes.push_back(engine::points::PointWrite{name, std::move(*converted)});
    }
    std::sort(writes.begin(), writes.end(), [&](const auto& a, const auto& b) {
        return find_point(points, a.name) < find_point(points, b.name);
    });
    engine::points::PointRequests built = engine::points::write_requests(points, writes);
    if (!built.ok()) {
        return refuse("out_of_range", (built.point.empty() ? std::string() : point_name(built.point) + ": ") +
                                          built.error + "; nothing was written");
    }
    PointOp op;
    op.requests = std::move(built.requests);
    return op;
}

PointOp point_read(const core::PointModel& points, const json* names) {
    if (names == nullptr) return refuse("missing_field", "field 'points' is required");
    if (!names->is_array() || names->empty()) {
        return refuse("invalid_field", "field 'points' must be a non-empty array of point names");
    }
    std::vector<std::string> wanted;
    for (const json& name : *names) {
        if (!name.is_string()) return refuse("invalid_field", "field 'points' must hold point names (strings)");
        const auto text = name.get<std::string>();
        if (find_point(points, text) == nullptr) {
            return refuse("invalid_field", point_name(text) + " is not a point of this device");
        }
        if (std::find(wanted.begin(), wanted.end(), text) == wanted.end()) wanted.push_back(text);
    }
    engine::points::PointRequests built = engine::points::read_requests(points, wanted);
    if (!built.ok()) return refuse("invalid_field", built.error);
    PointOp op;
    op.requests = std::move(built.requests);
    op.read_points = std::move(wanted);
    return op;
}

}  // namespace fieldbridge::northbound::mqtt
