#pragma once
/// @file point_commands.hpp
/// The two ops of a device with points (docs/mqtt.md, "Points: write and read"):
/// `{"op":"write","values":{"setpoint":21.5,"mode":"heat"}}`, all or nothing, and
/// `{"op":"read","points":["voltage"]}`, a fresh read answered with the values. The
/// JSON values are checked against the points here (known, writable, JSON type); the
/// engine's point codec encodes them (range, min / max) into the write requests. Pure.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/point.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::northbound::mqtt {

/// Whether a device with @p points takes `write` (a writable point) / `read` (any point).
[[nodiscard]] bool takes_point_write(const core::PointModel& points) noexcept;
[[nodiscard]] bool takes_point_read(const core::PointModel& points) noexcept;

/// The requests of one point op, or why not: @p kind is a CommandErrorKind's name
/// ("missing_field", "invalid_field", "out_of_range"), @p message names the point.
struct PointOp {
    std::vector<protocol::Request> requests;
    std::vector<std::string> read_points;  ///< `read`: the points to answer with
    std::string kind;
    std::string message;
    [[nodiscard]] bool ok() const noexcept { return kind.empty(); }
};

/// `write`: @p values is the command's `values` member (nullptr when absent).
[[nodiscard]] PointOp point_write(const core::PointModel& points, const nlohmann::json* values);
/// `read`: @p names is the command's `points` member (nullptr when absent).
[[nodiscard]] PointOp point_read(const core::PointModel& points, const nlohmann::json* names);

}  // namespace fieldbridge::northbound::mqtt
