#include "engine/profiles/generic_profile.hpp"

#include <algorithm>
#include <chrono>
#include <string>
#include <utility>

#include "engine/points/point_alarms.hpp"
#include "engine/points/point_codec.hpp"

namespace fieldbridge::engine {

namespace {

[[nodiscard]] WireFunctions generic_wire_functions() {
    namespace fn = protocol::fn;
    // What libmodbus' server and mbusd carry too: report server ID (FC11), mask write
    // (FC16) and read/write multiple registers (FC17), through the same block checks.
    return WireFunctions{{fn::read_coils, fn::read_discrete_inputs, fn::read_holding_registers,
                          fn::read_input_registers, fn::write_single_coil, fn::write_single_register,
                          fn::write_multiple_coils, fn::write_multiple_registers, fn::report_server_id,
                          fn::mask_write_register, fn::read_write_multiple_registers},
                         false, false};
}

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

GenericProfile::GenericProfile(const ProfileOptions& options)
    : GenericProfile(options, build_generic_map(options.blocks, options.points)) {}

GenericProfile::GenericProfile(const ProfileOptions& options, GenericMap map)
    : ModbusProfile(std::move(map.map), generic_wire_functions(), options, WordOrder::high_first),
      units_(std::move(map.units)),
      raised_(options.points.alarms.size(), false) {
    const auto& points = this->options().points.points;
    for (const core::AlarmRule& rule : this->options().points.alarms) {
        const auto it = std::find_if(points.begin(), points.end(),
                                     [&rule](const core::PointDef& p) { return p.name == rule.point; });
        alarm_points_.push_back(static_cast<std::size_t>(it - points.begin()));  // found: build_generic_map()
    }
}

std::optional<protocol::ExceptionCode> GenericProfile::validate(const protocol::Request& request,
                                                                const RegisterImage& image) const {
    if (const auto bad = ModbusProfile::validate(request, image)) {
        return bad;
    }
    const std::optional<RequestSpan> span = request_span(request);
    if (!span || !span->write || units_.empty()) {
        return std::nullopt;
    }
    const auto& points = options().points.points;
    const std::size_t end = std::size_t{span->address} + span->count;
    for (const PointUnit& u : units_) {
        if (u.table != span->table || u.end() <= span->address || u.address >= end) {
            continue;
        }
        if (std::holds_alternative<protocol::MaskWriteRegisterRequest>(request)) {
            // The value a mask leaves depends on the register's current one: only bits
            // may be masked, each a point of its own.
            const bool bits_only = std::all_of(u.points.begin(), u.points.end(),
                                               [&points](std::size_t i) { return points[i].bit.has_value(); });
            if (!bits_only) {
                return protocol::ExceptionCode::illegal_data_value;
            }
            continue;
        }
        // ModbusProfile::validate() let through only writes of whole units.
        const std::span<const std::uint16_t> registers(span->values.data() + (u.address - span->address), u.width);
        for (const std::size_t i : u.points) {
            if (!points::check_registers(points[i], registers).empty()) {
                return protocol::ExceptionCode::illegal_data_value;
            }
        }
    }
    return std::nullopt;
}

std::vector<PollUnit> GenericProfile::poll_units() const {
    std::vector<PollUnit> units;
    for (const GenericBlock& b : options().blocks) {
        auto more = map().poll_units(RegisterSpan{b.table, b.address, b.count}, PollClass::custom, b.period, false);
        units.insert(units.end(), more.begin(), more.end());
    }
    const core::PointModel& point_model = options().points;
    for (const PointUnit& u : units_) {
        // Each period a point of the unit asks for (merge_units() drops repeats).
        for (const std::size_t i : u.points) {
            const Duration period = std::chrono::duration_cast<Duration>(point_model.points[i].period);
            units.push_back(PollUnit{RegisterSpan{u.table, u.address, u.width}, PollClass::custom, period, false,
                                     point_model.max_gap});
        }
    }
    return units;
}

std::vector<std::uint16_t> GenericProfile::registers_of(const RegisterImage& image, std::size_t index) const {
    const core::PointDef& p = options().points.points[index];
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

bool GenericProfile::in_motion(const RegisterImage& /*image*/) const {
    return false;
}

DecodedState GenericProfile::decode_state(const RegisterImage& image) const {
    DecodedState state;
    const auto& points = options().points.points;
    for (std::size_t i = 0; i < points.size(); ++i) {
        const core::PointDef& p = points[i];
        const std::vector<std::uint16_t> registers = registers_of(image, i);
        if (registers.empty()) {
            continue;
        }
        points::PointValue value = points::decode(p, registers);
        if (!p.labels.empty()) {
            if (const auto* code = std::get_if<std::int64_t>(&value)) {
                const std::string_view label = points::label_of(p, *code);
                // A code the enum does not name: the code stands in for the label.
                state.fields.push_back(label.empty() ? Field{p.name, *code, p.unit}
                                                     : Field{p.name, std::string{label}, p.unit});
                state.fields.push_back(Field{p.name + "_code", *code, ""});
                continue;
            }
        }
        state.fields.push_back(Field{p.name, field_value(std::move(value)), p.unit});
    }
    return state;
}

std::vector<Alarm> GenericProfile::alarms(const RegisterImage& image) const {
    const core::PointModel& point_model = options().points;
    std::vector<Alarm> out;
    const std::lock_guard lock(alarm_mutex_);
    for (std::size_t r = 0; r < point_model.alarms.size(); ++r) {
        const core::AlarmRule& rule = point_model.alarms[r];
        const core::PointDef& point = point_model.points[alarm_points_[r]];
        const std::vector<std::uint16_t> registers = registers_of(image, alarm_points_[r]);
        raised_[r] = !registers.empty() && points::alarm_raised(rule, point, registers, raised_[r]);
        if (raised_[r]) {
            out.push_back(Alarm{rule.name, points::alarm_text(rule, point), severity_of(rule.severity),
                                "point " + point.name});
        }
    }
    return out;
}

}  // namespace fieldbridge::engine
