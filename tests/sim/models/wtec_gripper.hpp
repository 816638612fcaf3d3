#pragma once
/// @file wtec_gripper.hpp
/// The physical WTEC-485 parallel gripper (seed 003) behind both of its protocol
/// faces (wtec_ascii_model.hpp, wtec_rtu_model.hpp): position in encoder counts,
/// homing, grip state, motor enable, e-stop latch, currents, speeds, parameters.
///
/// Geometry (README.md has the reasoning): positions count from the homing end, which
/// is the open end for homing mode FC / init direction 1 (the default, as in the
/// manual's B example) and the closed end for FD / 2. Position 0 is where homing
/// stops, 3 counts off the home-side stop: a release to the limit presses that stop
/// and ends at -3, as the manual's `I` example shows (FFFFFFFD, state 05). The far
/// stop is at `stroke`. Closing meets an object placed with place_object().
///
/// Speeds: a move at speed byte s (0-0xFF) covers 2 * stroke * s / 255 counts per
/// second (a full stroke in 0.5 s at 0xFF); homing runs at the `B` homing speed
/// (at least 1000 counts/s), then waits the `B` confirm time in ms.
/// Currents (`I`): 0 with the motor released, the grip current while closing or
/// holding an object, the release current (`W`) while opening, 3 at rest (the `I`
/// example reads 03 after a release).
///
/// Force (docs/registers.md, wtec-rtu): there is one grip current, the `N` max current;
/// `C` sets it. The Modbus force 0x0103 is that current as a share of the `R` max
/// current ("the max running current set over ASCII is the current at 100 %", seed 003
/// table 2.5): force = round(N max x 100 / R max), capped at 100; writing force f sets
/// N max = round(f x R max / 100). Both faces therefore read the same gripper alike.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "models/bus_device.hpp"
#include "models/linear_move.hpp"
#include "protocol/wtec_ascii_commands.hpp"

namespace fieldbridge::sim {

class WtecGripper {
public:
    /// The strokes a model accepts (encoder counts; DeviceOptions::wtec_stroke).
    static constexpr std::uint32_t min_stroke = 100;
    static constexpr std::uint32_t max_stroke = 10'000'000;

    /// @p stroke encoder counts from end to end (DeviceOptions::wtec_stroke).
    explicit WtecGripper(std::uint32_t stroke);

    void advance(Clock::time_point now);

    // ---- actions ------------------------------------------------------------------
    /// 0x0100 = 1 (Modbus-RTU face): enables the motor, clears the e-stop latch,
    /// homes (seed 003 table 2.12: only initialising unlocks an e-stop).
    void initialise(Clock::time_point now);
    /// `G` (ASCII face): clears the e-stop latch, enables the motor and homes, except
    /// after `a0`: a motor released on command stays released until `a1` (seed 003
    /// command 3), so `G` alone is acknowledged and nothing happens.
    void home(Clock::time_point now);
    /// 0x0102 = 1: stops, releases the motor; latched until the next home().
    void emergency_stop(Clock::time_point now);
    /// `a`: enable (refused while the e-stop latch is set) or release the motor.
    void set_motor_enabled(bool enable, Clock::time_point now);
    /// `D` / 0x0105: stores the target and moves there when homed, enabled and not
    /// e-stopped. Returns whether it moves.
    bool move_to(std::int32_t target, Clock::time_point now);
    /// `E`: false (nothing done) when not homed, released or e-stopped.
    bool grip_action(protocol::wtec::GripAction action, Clock::time_point now);
    /// `Z`: after an encoder calibration the homing reference is lost.
    void calibrate_encoder(Clock::time_point now);

    // ---- state --------------------------------------------------------------------
    [[nodiscard]] std::uint32_t stroke() const noexcept { return stroke_; }
    [[nodiscard]] std::int32_t position() const noexcept { return static_cast<std::int32_t>(position_); }
    /// `g` code: 00 not homed, 01 homed, 02 failed, 09 homing.
    [[nodiscard]] std::uint8_t homing_state() const noexcept;
    /// `d` code: 00 moving, 01 reached, 02 gripped, 05 released to limit, 06 closed to
    /// limit without object, 11 motor released / not homed.
    [[nodiscard]] std::uint8_t grip_state() const noexcept;
    [[nodiscard]] std::uint8_t current() const noexcept;
    [[nodiscard]] bool enabled() const noexcept { return enabled_; }
    /// Released by `a0` (until `a1`) or e-stopped: `D` is refused (echoed) on the
    /// ASCII face. Not at power-up: there `D` only stores the target.
    [[nodiscard]] bool motor_released() const noexcept { return released_ || estop_; }
    [[nodiscard]] bool estop_latched() const noexcept { return estop_; }
    [[nodiscard]] bool homed() const noexcept { return homed_; }

    // ---- parameters ---------------------------------------------------------------
    [[nodiscard]] const protocol::wtec::HomingParams& homing_params() const noexcept { return homing_; }
    void set_homing_params(const protocol::wtec::HomingParams& params) noexcept { homing_ = params; }
    [[nodiscard]] const protocol::wtec::GripperParams& gripper_params() const noexcept { return gripper_; }
    /// `n`: stores the parameters (the target too, without moving).
    void set_gripper_params(const protocol::wtec::GripperParams& params) noexcept { gripper_ = params; }
    [[nodiscard]] const protocol::wtec::DriverParams& driver_params() const noexcept { return driver_; }
    void set_driver_params(const protocol::wtec::DriverParams& params) noexcept { driver_ = params; }
    [[nodiscard]] const protocol::wtec::Pid& pid() const noexcept { return pid_; }
    void set_pid(const protocol::wtec::Pid& pid) noexcept { pid_ = pid; }
    [[nodiscard]] const protocol::wtec::ReleaseParams& release_params() const noexcept { return release_; }
    void set_release_params(const protocol::wtec::ReleaseParams& params) noexcept { release_ = params; }

    /// `C`: the grip current, which is the `N` max current (the force follows).
    void set_grip_current(std::uint8_t current) noexcept { gripper_.max_current = current; }
    [[nodiscard]] std::uint8_t grip_current() const noexcept { return gripper_.max_current; }
    /// 0x0103 write: N max current = round(@p percent x `R` max current / 100), at most 0xFF.
    void set_force_percent(std::uint16_t percent) noexcept;
    /// 0x0103 read: round(N max current x 100 / `R` max current), capped at 100 (100
    /// with an `R` max current of 0).
    [[nodiscard]] std::uint16_t force_percent() const noexcept;
    /// 0x0104: speed 1-100 % of the `N` speed byte range.
    void set_speed_percent(std::uint16_t percent) noexcept;
    [[nodiscard]] std::uint16_t speed_percent() const noexcept;
    /// 0x0300: 1 open, 2 closed; the same setting as the `B` homing mode FC / FD.
    void set_init_direction(std::uint16_t direction) noexcept;
    [[nodiscard]] std::uint16_t init_direction() const noexcept;
    /// 0x0302 / `U`.
    void set_saved(bool saved) noexcept { saved_ = saved; }
    [[nodiscard]] bool saved() const noexcept { return saved_; }

    // ---- faults and test fixtures -------------------------------------------------
    /// An object whose width is @p hundredths_of_percent of the full opening (0-10000),
    /// or nullopt to take it away.
    void place_object(std::optional<std::int64_t> hundredths_of_percent) noexcept { object_ = hundredths_of_percent; }
    /// The next homing ends with `g` 02 (failed).
    void fail_next_homing() noexcept { fail_next_homing_ = true; }
    /// Clears an injected or past homing failure (back to "not homed").
    void clear_faults() noexcept;
    /// Puts the encoder at @p counts (a test fixture, e.g. after a manual push).
    void set_position(std::int32_t counts, Clock::time_point now);

private:
    enum class Goal : std::uint8_t { target, open_stop, closed_stop };

    void start_motion(std::int64_t target, Goal goal, std::int64_t speed, Clock::time_point now);
    [[nodiscard]] std::int64_t speed_from(std::uint8_t speed_byte) const noexcept;
    [[nodiscard]] bool home_is_open() const noexcept { return frame_home_open_; }
    [[nodiscard]] std::int64_t open_stop() const noexcept;
    [[nodiscard]] std::int64_t closed_stop() const noexcept;
    [[nodiscard]] bool can_move() const noexcept { return homed_ && enabled_ && !estop_ && !homing_in_progress_; }

    std::uint32_t stroke_;
    std::int64_t position_ = 0;
    bool frame_home_open_ = true;  ///< homing direction of the last homing (position frame)
    bool homed_ = false;
    bool homing_failed_ = false;
    bool homing_in_progress_ = false;
    bool fail_next_homing_ = false;
    bool enabled_ = false;
    bool released_ = false;  ///< `a0` was the last `a`: only `a1` enables again
    bool estop_ = false;
    bool saved_ = false;
    bool last_action_grip_ = false;
    bool closing_ = false;
    std::uint8_t outcome_ = protocol::wtec::grip_state::reached;
    std::optional<LinearMove> motion_;
    bool motion_meets_object_ = false;
    Goal motion_goal_ = Goal::target;
    Clock::time_point homing_done_at_{};
    Clock::time_point last_advance_{};
    std::optional<std::int64_t> object_;

    protocol::wtec::HomingParams homing_;
    protocol::wtec::GripperParams gripper_;
    protocol::wtec::DriverParams driver_;
    protocol::wtec::Pid pid_;
    protocol::wtec::ReleaseParams release_;
};

}  // namespace fieldbridge::sim

namespace fieldbridge::sim {

/// Control commands shared by both WTEC faces: "estop", "object <percent of the full
/// opening>|none", "fail-homing", "clear", "position <counts>". @p type names the face
/// in error texts.
[[nodiscard]] std::string wtec_control(WtecGripper& gripper, std::string_view type,
                                       std::string_view command, Clock::time_point now);

}  // namespace fieldbridge::sim
