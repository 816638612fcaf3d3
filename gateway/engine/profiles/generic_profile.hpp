#pragma once
/// @file generic_profile.hpp
/// A generic Modbus-RTU device: its register blocks and poll periods come from the
/// configuration (spec §5). The blocks are the known map: a request outside them
/// is answered 0x02 locally; writes are allowed only to writable blocks of coils
/// and holding registers. Function codes: 01-06, 0F, 10, and 11 (report server ID,
/// passed through), 16 (mask write: the register is read again after it) and 17
/// (read/write multiple registers: both spans checked against the blocks). Adjacent blocks with the same period are read together.
/// Nothing is decoded (MQTT shows the raw registers); no alarms, never in motion, no
/// MQTT operations beyond the raw register ops.

#include "engine/profiles/modbus_profile.hpp"

namespace fieldbridge::engine {

class GenericProfile final : public ModbusProfile {
public:
    /// Throws ProfileError for no blocks, a count outside 1-125 (1-2000 bits), a
    /// block past 0xFFFF, or a writable block of a read-only table.
    explicit GenericProfile(const ProfileOptions& options);

    [[nodiscard]] DeviceType type() const noexcept override { return DeviceType::modbus; }
    [[nodiscard]] bool in_motion(const RegisterImage& image) const override;
    [[nodiscard]] DecodedState decode_state(const RegisterImage& image) const override;
    [[nodiscard]] std::vector<Alarm> alarms(const RegisterImage& image) const override;
    /// None of its own: the raw register ops only (docs/mqtt.md, "Every device type").
    [[nodiscard]] OperationSet operations() const override { return OperationSet{}; }

private:
    [[nodiscard]] std::vector<PollUnit> poll_units() const override;
};

}  // namespace fieldbridge::engine
