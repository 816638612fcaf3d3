#include "engine/profiles/wtec_rtu_profile.hpp"

#include <utility>

#include "engine/profiles/builtin_map.hpp"
#include "engine/profiles/wtec_common.hpp"

namespace fieldbridge::engine {

namespace {

[[nodiscard]] WireFunctions wtec_rtu_wire_functions() {
    // Seed 003 §2.1.1: "常见功能码有 03、06"; FC16 is translated to FC06s.
    return WireFunctions{{protocol::fn::read_holding_registers, protocol::fn::write_single_register,
                          protocol::fn::write_multiple_registers},
                         false, true};
}

}  // namespace

IdentificationRead wtec_rtu_identification() noexcept { return IdentificationRead{wtec_reg::device_id, 1}; }

WtecRtuProfile::WtecRtuProfile(const ProfileOptions& options)
    : ModbusProfile(builtin_register_map(DeviceType::wtec_rtu, options), wtec_rtu_wire_functions(), options,
                    WordOrder::high_first),
      state_(builtin_state_points(DeviceType::wtec_rtu, options)) {}

std::vector<PollUnit> WtecRtuProfile::poll_units() const {
    using namespace wtec_reg;
    std::vector<PollUnit> units;
    const auto add = [&units](std::vector<PollUnit> more) { units.insert(units.end(), more.begin(), more.end()); };
    // Status fast; the holes between them are never bridged (rule 8): three reads.
    add(units_for(Table::holding, init_state, 1, PollClass::fast, true));
    add(units_for(Table::holding, grip_state, 1, PollClass::fast, true));
    add(units_for(Table::holding, instant_position, 1, PollClass::fast, true));
    // Settings slow: 0x0102-0x0105 in one read, 0x0300, 0x0302-0x0303.
    add(units_for(Table::holding, estop, 4, PollClass::slow));
    add(units_for(Table::holding, init_direction, 1, PollClass::slow));
    add(units_for(Table::holding, save, 2, PollClass::slow));
    return units;
}

bool WtecRtuProfile::in_motion(const RegisterImage& image) const {
    return wtec_in_motion(image);
}

DecodedState WtecRtuProfile::decode_state(const RegisterImage& image) const {
    return state_.decode(image);
}

std::vector<Alarm> WtecRtuProfile::alarms(const RegisterImage& image) const {
    return state_.alarms(image);
}

OperationSet WtecRtuProfile::operations() const { return wtec_operations(); }

}  // namespace fieldbridge::engine
