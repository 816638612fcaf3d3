#pragma once
/// @file wtec_rtu_profile.hpp
/// WTEC-485 parallel gripper in its Modbus-RTU mode (seed 003 part 2; spec §5).
///
/// Holding registers 0x0100, 0x0102-0x0105, 0x0200, 0x0202, 0x0204, 0x0300,
/// 0x0302, 0x0303 (wtec_common.hpp). The gripper knows FC03 and FC06 (seed 003
/// §2.1.1); a client's FC16 goes out as one FC06 per register, in order, so a
/// PLC program written for the ASCII view (which takes FC16) works unchanged.
/// 0x0201, 0x0203 and 0x0301 are holes: status is polled as three reads.
/// State fields and alarms: the points and alarms of its definition
/// (config/devices/wtec-rtu.yaml).

#include "engine/profiles/modbus_profile.hpp"
#include "engine/profiles/point_state.hpp"

namespace fieldbridge::engine {

/// The scan's read of the device ID register (seed 003 table 2.11 "设备ID"): a WTEC-485
/// in RTU mode answers the address it answered from.
[[nodiscard]] IdentificationRead wtec_rtu_identification() noexcept;

class WtecRtuProfile final : public ModbusProfile {
public:
    explicit WtecRtuProfile(const ProfileOptions& options);

    [[nodiscard]] DeviceType type() const noexcept override { return DeviceType::wtec_rtu; }
    [[nodiscard]] bool in_motion(const RegisterImage& image) const override;
    [[nodiscard]] DecodedState decode_state(const RegisterImage& image) const override;
    [[nodiscard]] std::vector<Alarm> alarms(const RegisterImage& image) const override;
    [[nodiscard]] OperationSet operations() const override;

private:
    [[nodiscard]] std::vector<PollUnit> poll_units() const override;

    PointState state_;
};

}  // namespace fieldbridge::engine
