#pragma once
/// @file wtec_ascii_profile.hpp
/// WTEC-485 in its vendor ASCII mode, shown to Modbus clients through the uniform
/// register view: the same holding registers as the gripper's own Modbus-RTU mode
/// (wtec_common.hpp), plus an extension block of input registers from 0x1000 with
/// what only the ASCII protocol tells (spec §5; docs/registers.md has the table).
///
/// Reads are served from the image, filled by polling `I`, `g` (fast), `N`, `R`,
/// `B` (slow) and `A`, `P`, `W` (at start); an on-demand read sends the commands
/// that fill the registers asked for. Writes become ASCII commands, one per
/// register, in address order (FC16 over several registers: several commands):
///   0x0100 = 1     -> `a1` (enable the motor), then `G` (home)
///   0x0102 = 1     -> `a0` (release the motor); the gateway latches 0x0102 = 1
///                     until an acknowledged `G` clears it
///   0x0103 = f %   -> `C` grip current = round(f x R.max_current / 100) (C sets the
///                     N max current; force reads round(N.max x 100 / R.max))
///   0x0104 = s %   -> `n` with the other N fields as read, speed = ceil(s x 255 / 100)
///   0x0105 = p     -> `D` target = ceil(p x stroke / 100) (D moves there)
///   0x0300 = 1 / 2 -> `b` with the other B fields as read, mode 0xFC / 0xFD
///   0x0302 = 1     -> `U` (protected)
///   0x0303 = id    -> `i` id (protected)
/// A write that needs device data not read yet (R for force, N for speed, B for
/// the init direction) is answered 0x0B (gateway target failed) until it is read.
/// A `D` (or `E`) the gripper echoes back instead of acknowledging was not executed
/// (motor released, not homed): answered 0x04 (server device failure) with a notice.

#include <cstdint>
#include <optional>
#include <vector>

#include "engine/profiles/point_state.hpp"
#include "engine/profiles/device_profile.hpp"
#include "engine/profiles/register_map.hpp"

namespace fieldbridge::engine {

/// ceil(@p percent x @p full / 100), @p percent clamped to 100.
[[nodiscard]] std::uint32_t wtec_percent_to_raw(std::uint16_t percent, std::uint32_t full) noexcept;
/// The inverse: the smallest percentage whose wtec_percent_to_raw() is @p raw (so a
/// value written reads back the same whenever @p full >= 100), or the nearest one
/// when no percentage gives @p raw; 0 for @p raw <= 0 or @p full == 0, 100 for
/// @p raw >= @p full.
[[nodiscard]] std::uint16_t wtec_raw_to_percent(std::int64_t raw, std::uint32_t full) noexcept;

/// Force 0x0103 from the grip current (`N` max current, also set by `C`) over the
/// current at 100 % (`R` max current, seed 003 table 2.5): round(@p current x 100 /
/// @p full), at most 100; 0 when @p full is 0.
[[nodiscard]] std::uint16_t wtec_force_percent(std::uint32_t current, std::uint32_t full) noexcept;
/// The `C` grip current for force @p percent (clamped to 100): round(@p percent x
/// @p full / 100). Every percentage reads back unchanged when @p full >= 100.
[[nodiscard]] std::uint32_t wtec_force_current(std::uint16_t percent, std::uint32_t full) noexcept;

/// Uniform grip state (0x0202) from the `d` / `I` code: 00->0, 01->1, 02->2, 05->1
/// (released to the limit: stopped, no object), 06->1 (closed to the limit without
/// an object), 0x11->11 (motor released); other codes are passed as they are.
[[nodiscard]] std::uint16_t wtec_uniform_grip_state(std::uint8_t code) noexcept;
/// Uniform init state (0x0200) from the `g` code: 00->0, 01->1, 02->2, 03->2
/// (beyond the limit: a failed homing), 09->9; other codes are passed as they are.
[[nodiscard]] std::uint16_t wtec_uniform_init_state(std::uint8_t code) noexcept;

class WtecAsciiProfile final : public DeviceProfile {
public:
    /// Throws ProfileError without a stroke (or with 0).
    explicit WtecAsciiProfile(const ProfileOptions& options);

    [[nodiscard]] DeviceType type() const noexcept override { return DeviceType::wtec_ascii; }
    [[nodiscard]] Bus bus() const noexcept override { return Bus::wtec_ascii; }
    [[nodiscard]] core::BusAddress broadcast_address() const noexcept override { return core::BusAddress{0}; }

    [[nodiscard]] std::optional<protocol::ExceptionCode> validate(const protocol::Request& request,
                                                                  const RegisterImage& image) const override;
    [[nodiscard]] Classification classify(const protocol::Request& request) const override;
    [[nodiscard]] std::vector<Payload> to_line(const protocol::Request& request,
                                               const RegisterImage& image) const override;
    [[nodiscard]] PollPlan poll_plan() const override;
    [[nodiscard]] ApplyResult apply(const Payload& sent, const Reply& reply, RegisterImage& image,
                                    TimePoint now) const override;
    [[nodiscard]] protocol::Response respond(const protocol::Request& request, std::span<const Reply> replies,
                                             const RegisterImage& image) const override;
    [[nodiscard]] bool in_motion(const RegisterImage& image) const override;
    [[nodiscard]] DecodedState decode_state(const RegisterImage& image) const override;
    [[nodiscard]] std::vector<Alarm> alarms(const RegisterImage& image) const override;
    [[nodiscard]] OperationSet operations() const override;

    [[nodiscard]] const RegisterMap& map() const noexcept { return map_; }
    [[nodiscard]] std::uint32_t stroke() const noexcept { return stroke_; }

private:
    [[nodiscard]] bool apply_reply(const protocol::wtec::Command& command, const protocol::wtec::Reply& reply,
                                   RegisterImage& image, TimePoint now) const;
    void refresh_gateway_registers(RegisterImage& image, TimePoint now) const;

    RegisterMap map_;
    ProfileOptions options_;
    std::uint32_t stroke_ = 0;
    /// The state fields and alarms: the points of the definition (wtec-ascii.yaml).
    PointState state_;
};

}  // namespace fieldbridge::engine
