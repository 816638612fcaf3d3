#pragma once
/// @file excd_profile.hpp
/// EXCD203MB stepper controller over Modbus-RTU (seed 002; spec §5).
///
/// Holding registers only, FC03 / FC06 / FC10 (seed 002 §2). Many values are 32-bit
/// pairs; a write must cover the whole pair (0x02 otherwise), a read of half a pair
/// is allowed. The northbound view is always high word first; with `word_order:
/// low_first` the profile swaps the two words of every pair on the wire, in both
/// directions, and widens reads that cut a pair. Broadcast address 0xFF (§5).
/// Protected (refused with 0x01 unless allow_protected): idon 0x001F, id 0x0020,
/// baude 0x002B, mbus 0x003A, save 0x0303.
/// State fields and the alarm: the points and alarms of its definition
/// (config/devices/excd203mb.yaml).

#include <cstdint>
#include <optional>

#include "engine/profiles/modbus_profile.hpp"
#include "engine/profiles/point_state.hpp"

namespace fieldbridge::engine {

/// The MQTT operations (docs/mqtt.md, "excd203mb"): abs, rel, home, stop, jog,
/// jog_stop (seed 002 "運轉指令"). 32-bit values high word first.
[[nodiscard]] OperationSet excd_operations();

/// The scan's read of `ver` (seed 002 section 4, a 32-bit query register): an
/// EXCD203MB answers it with two registers.
[[nodiscard]] IdentificationRead excd_identification() noexcept;

class ExcdProfile final : public ModbusProfile {
public:
    explicit ExcdProfile(const ProfileOptions& options);

    [[nodiscard]] DeviceType type() const noexcept override { return DeviceType::excd203mb; }
    [[nodiscard]] core::BusAddress broadcast_address() const noexcept override { return core::BusAddress{0xFF}; }
    [[nodiscard]] bool in_motion(const RegisterImage& image) const override;
    [[nodiscard]] DecodedState decode_state(const RegisterImage& image) const override;
    [[nodiscard]] std::vector<Alarm> alarms(const RegisterImage& image) const override;
    [[nodiscard]] OperationSet operations() const override { return excd_operations(); }

private:
    [[nodiscard]] std::optional<protocol::ExceptionCode> check_value(const RegisterDef& def,
                                                                     std::uint16_t unit_address,
                                                                     std::int64_t value,
                                                                     const RegisterImage& image) const override;
    [[nodiscard]] std::vector<PollUnit> poll_units() const override;

    PointState state_;
};

}  // namespace fieldbridge::engine
