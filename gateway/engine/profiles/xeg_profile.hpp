#pragma once
/// @file xeg_profile.hpp
/// HIWIN XEG-C2 electric gripper controller over Modbus-RTU (seed 001; spec §5).
///
/// Map (seed 001 §3): discrete inputs 0x0000-0x0007 (DI) and 0x0010-0x0017 (DO);
/// input registers 0x0300 position (0.01 mm), 0x0301 status 0-7, 0x0303-0x0306
/// firmware; holding registers 0x0600 model, 0x0601 trigger, 0x0610 reset, 0x0620
/// stop, 0x0630-0x0632 move, 0x0640-0x0646 expert (the model is writable, limited
/// to the §3.3 codes). The controller knows FC02, 03,
/// 04, 07 and 10 only (§4.1): a client's FC06 goes out as FC16 with one register.
/// Move and expert values are checked against the model's ranges (§3.4.2). The MQTT
/// state and alarms are the points of the definition (config/devices/hiwin-xeg.yaml).

#include <cstdint>
#include <optional>
#include <string_view>

#include "engine/profiles/modbus_profile.hpp"
#include "engine/profiles/point_state.hpp"

namespace fieldbridge::engine {

/// Model-dependent limits (seed 001 §3.4.2 table), in register units (0.01 mm,
/// 0.01 mm/s, %).
struct XegModelLimits {
    std::uint16_t model = 0;  ///< 0x0600 value
    std::string_view name;
    std::uint16_t stroke = 0;      ///< move / holding stroke maximum
    std::uint16_t speed = 0;       ///< move speed maximum
    std::uint16_t hold_speed = 0;  ///< holding speed maximum
    std::uint16_t force_min = 0;   ///< holding force minimum (maximum is 100 %)
};

/// The limits of @p model; nullopt for a value the manual does not list.
[[nodiscard]] std::optional<XegModelLimits> xeg_model_limits(std::uint16_t model) noexcept;

/// What the gateway checks against while the model is unknown (not read yet, or a
/// value the manual does not list): the widest of every range, i.e. XEG-64's
/// stroke and speeds with the lowest force minimum (40 %).
[[nodiscard]] XegModelLimits xeg_widest_limits() noexcept;

/// The scan's read of the model register (seed 001 §3.3 "EG type"): an XEG answers one
/// of the model codes xeg_model_limits() knows.
[[nodiscard]] IdentificationRead xeg_identification() noexcept;

/// Seed 001 §4.2.4: the text of an FC07 exception status code.
[[nodiscard]] std::string_view xeg_exception_status_text(std::uint8_t code) noexcept;

/// The MQTT operations (docs/mqtt.md, "hiwin-xeg"): reset, stop, move, expert,
/// trigger (seed 001 §3.4).
[[nodiscard]] OperationSet xeg_operations();

class XegProfile final : public ModbusProfile {
public:
    explicit XegProfile(const ProfileOptions& options);

    [[nodiscard]] DeviceType type() const noexcept override { return DeviceType::hiwin_xeg; }
    [[nodiscard]] bool in_motion(const RegisterImage& image) const override;
    [[nodiscard]] DecodedState decode_state(const RegisterImage& image) const override;
    [[nodiscard]] std::vector<Alarm> alarms(const RegisterImage& image) const override;
    [[nodiscard]] OperationSet operations() const override { return xeg_operations(); }
    /// As ModbusProfile::apply(); an acknowledged write of the model (0x0600) asks
    /// for a read of it back (follow_up), as Appendix 1 does after writing it.
    [[nodiscard]] ApplyResult apply(const Payload& sent, const Reply& reply, RegisterImage& image,
                                    TimePoint now) const override;

private:
    [[nodiscard]] std::optional<protocol::ExceptionCode> check_value(const RegisterDef& def,
                                                                     std::uint16_t unit_address,
                                                                     std::int64_t value,
                                                                     const RegisterImage& image) const override;
    [[nodiscard]] std::vector<PollUnit> poll_units() const override;
    void on_device_exception(const protocol::Request& sent, protocol::ExceptionCode code,
                             ApplyResult& result) const override;
    void apply_other(const protocol::Request& sent, const protocol::Response& reply, RegisterImage& image,
                     TimePoint now, ApplyResult& result) const override;

    /// The state fields and alarms: the points of the definition (hiwin-xeg.yaml).
    PointState state_;
};

}  // namespace fieldbridge::engine
