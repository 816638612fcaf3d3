#pragma once
/// @file generic_profile.hpp
/// A generic Modbus-RTU device: its map comes from the configuration (spec §5,
/// issue 25): named, typed points (from a device definition file or inline) and raw
/// register blocks, each polled at its own period. Points and blocks are the known
/// map (generic_map.hpp): a request outside them is answered 0x02 locally; writes are
/// allowed only to writable blocks of coils and holding registers and to writable
/// points, whose values are checked as the point reads them (docs/modbus-tcp.md,
/// "Point checks on writes"). Function codes: 01-06, 0F, 10, and 11 (report server
/// ID, passed through), 16 (mask write: the register is read again after it) and 17
/// (read/write multiple registers: both spans checked).
///
/// Poll plan: blocks as their map units, merged where they touch; points at their own
/// periods, merged with neighbours across gaps of at most `max_gap` registers that no
/// point names (split at the gaps for good when the device refuses the read).
/// State: one field per point in engineering units (enum points: the label and
/// `<name>_code`); alarms from the points' rules, with hysteresis. Never in motion;
/// no MQTT operations of its own (the raw register ops, and the point ops MQTT
/// derives from the points).

#include <vector>

#include "engine/profiles/generic_map.hpp"
#include "engine/profiles/modbus_profile.hpp"
#include "engine/profiles/point_state.hpp"

namespace fieldbridge::engine {

class GenericProfile final : public ModbusProfile {
public:
    /// Throws ProfileError for no blocks and no points, a block count outside 1-125
    /// (1-2000 bits), a block past 0xFFFF, a writable block of a read-only table, or a
    /// point the map cannot hold (build_generic_map()).
    explicit GenericProfile(const ProfileOptions& options);

    [[nodiscard]] DeviceType type() const noexcept override { return DeviceType::modbus; }
    /// ModbusProfile's checks, then: 0x03 for a write whose value of a point, decoded as
    /// the point reads it, is NaN / infinite, outside its min / max or an enum code
    /// without a label; 0x03 for a mask write (FC16) of a register holding any point
    /// but `bit:` points.
    [[nodiscard]] std::optional<protocol::ExceptionCode> validate(const protocol::Request& request,
                                                                  const RegisterImage& image) const override;
    [[nodiscard]] bool in_motion(const RegisterImage& image) const override;
    [[nodiscard]] DecodedState decode_state(const RegisterImage& image) const override;
    /// The raised rules. Hysteresis needs to know what was raised at the last call:
    /// that memory is this object's (one profile per device, made by the engine), so
    /// this is the one const method with a side effect, guarded by a mutex.
    [[nodiscard]] std::vector<Alarm> alarms(const RegisterImage& image) const override;
    /// None of its own: the raw register ops only (docs/mqtt.md, "Every device type").
    [[nodiscard]] OperationSet operations() const override { return OperationSet{}; }

    /// The point units of the map (by table, then address).
    [[nodiscard]] const std::vector<PointUnit>& point_units() const noexcept { return units_; }

private:
    GenericProfile(const ProfileOptions& options, GenericMap map);
    [[nodiscard]] std::vector<PollUnit> poll_units() const override;

    std::vector<PointUnit> units_;
    PointState state_;
};

}  // namespace fieldbridge::engine
