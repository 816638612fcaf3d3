#pragma once
/// @file point_requests.hpp
/// The Modbus requests that write or read named points (MQTT `write` / `read` ops,
/// docs/mqtt.md): pure functions of a device's point model, no I/O.

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/point.hpp"
#include "engine/points/point_codec.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::engine::points {

struct PointWrite {
    std::string name;
    PointValue value;
};

struct PointRequests {
    std::vector<protocol::Request> requests;
    std::string error;  ///< for operators: names the point and what is wrong
    std::string point;  ///< the point the error is about
    [[nodiscard]] bool ok() const noexcept { return error.empty(); }
};

/// The point named @p name; nullptr when the model has none.
[[nodiscard]] const core::PointDef* find_point(const core::PointModel& model, std::string_view name) noexcept;

/// All or nothing: an unknown point, a read-only one, a wrong type or a value out of
/// range refuses the whole set (error names the point); else the write requests in the
/// given order (FC05 coil, FC06 one register, FC16 several; a writable `bit:` point of a
/// holding register: FC22 mask write, which leaves the register's other bits alone).
[[nodiscard]] PointRequests write_requests(const core::PointModel& model, std::span<const PointWrite> writes);

/// Read requests covering the named points (merged where adjacent or overlapping, up
/// to 125 registers / 2000 bits a read; by table, then address), or an error naming an
/// unknown point. No name: no request.
[[nodiscard]] PointRequests read_requests(const core::PointModel& model, std::span<const std::string> names);

}  // namespace fieldbridge::engine::points
