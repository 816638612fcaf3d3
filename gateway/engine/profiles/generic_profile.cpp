#include "engine/profiles/generic_profile.hpp"

#include <algorithm>
#include <chrono>
#include <string>
#include <utility>

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

}  // namespace

GenericProfile::GenericProfile(const ProfileOptions& options)
    : GenericProfile(options, build_generic_map(options.blocks, options.points)) {}

GenericProfile::GenericProfile(const ProfileOptions& options, GenericMap map)
    : ModbusProfile(std::move(map.map), generic_wire_functions(), options, WordOrder::high_first),
      units_(std::move(map.units)),
      state_(options.points) {}

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

bool GenericProfile::in_motion(const RegisterImage& /*image*/) const {
    return false;
}

DecodedState GenericProfile::decode_state(const RegisterImage& image) const {
    return state_.decode(image);
}

std::vector<Alarm> GenericProfile::alarms(const RegisterImage& image) const {
    return state_.alarms(image);
}

}  // namespace fieldbridge::engine
