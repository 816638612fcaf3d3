#include "models/wtec_gripper.hpp"

#include <chrono>

#include "models/control_words.hpp"

namespace fieldbridge::sim {
namespace {

namespace wtec = protocol::wtec;

// seed 003 command 12 example: FFFFFFFD after a release to the limit.
constexpr std::int64_t home_stop = -3;
constexpr std::uint8_t rest_current = 0x03;  // same example: current 03 at rest
constexpr std::int64_t min_homing_speed = 1000;
constexpr std::uint8_t homing_mode_open = 0xFC;    // reverse collision homing (B example)
constexpr std::uint8_t homing_mode_closed = 0xFD;  // forward collision homing
constexpr std::int64_t full_object = 10000;        // object width unit: 0.01 %

std::int64_t rounded_div(std::int64_t num, std::int64_t den) noexcept {
    return den == 0 ? 0 : (num + den / 2) / den;
}

}  // namespace

WtecGripper::WtecGripper(std::uint32_t stroke) : stroke_(stroke) {
    // Power-up parameters are the manual's own examples (seed 003 commands 4, 14, 16,
    // 18, 21), except the N target (0: the jaws are at position 0) and home-at-power-up
    // (0: the Modbus example reads 0x0200 = 0, "not initialized", after power-up). The
    // grip current is N's 0x3F; R's max current (decoded by position) is 0x3F too, so
    // the force reads 100 % until `C`, `n` or 0x0103 changes it.
    homing_ = {homing_mode_open, 0x7530, 0x30D40, 0x3E8, 0x41, 1, 0xC8, 0x989680};
    gripper_ = {0, 0x3F, 0xFF, 0x0A, 0};
    driver_ = {0x0007A120, 0x004C4B40, 0x3F, 0, 0x03, 0x02, 0x2710, 0x00000104, 0};
    pid_ = {0x0080, 0x0000, 0x0090};
    release_ = {0x5C, 0xFF};
}

void WtecGripper::advance(Clock::time_point now) {
    if (now < last_advance_) now = last_advance_;
    last_advance_ = now;
    if (motion_) {
        position_ = motion_->position_at(now);
        if (motion_->done_at(now)) {
            motion_.reset();
            if (!homing_in_progress_) {
                if (motion_meets_object_) {
                    outcome_ = wtec::grip_state::gripped;
                } else if (motion_goal_ == Goal::open_stop) {
                    outcome_ = wtec::grip_state::released_to_limit;
                } else if (motion_goal_ == Goal::closed_stop) {
                    outcome_ = wtec::grip_state::closed_without_object;
                } else {
                    outcome_ = wtec::grip_state::reached;
                }
            }
        }
    }
    if (homing_in_progress_ && !motion_ && now >= homing_done_at_) {
        homing_in_progress_ = false;
        homed_ = !fail_next_homing_;
        homing_failed_ = fail_next_homing_;
        fail_next_homing_ = false;
        outcome_ = wtec::grip_state::reached;
    }
}

void WtecGripper::initialise(Clock::time_point now) {
    released_ = false;  // the RTU mode has no `a`: initialising enables the motor
    home(now);
}

void WtecGripper::home(Clock::time_point now) {
    advance(now);
    estop_ = false;  // seed 003 table 2.12: the e-stop is only unlocked by initialization
    if (released_) return;  // released by `a0`: only `a1` enables it (seed 003 command 3)
    enabled_ = true;
    homed_ = false;
    homing_failed_ = false;
    homing_in_progress_ = true;
    const bool open = init_direction() == 1;
    if (open != frame_home_open_) {
        // Positions count from the new homing end.
        position_ = static_cast<std::int64_t>(stroke_) - position_;
        frame_home_open_ = open;
    }
    const std::int64_t speed = homing_.speed > min_homing_speed ? homing_.speed : min_homing_speed;
    closing_ = false;
    motion_meets_object_ = false;
    motion_goal_ = Goal::target;
    motion_.emplace(now, position_, 0, speed);
    homing_done_at_ = motion_->end() + std::chrono::milliseconds(homing_.confirm_time);
}

void WtecGripper::emergency_stop(Clock::time_point now) {
    advance(now);
    motion_.reset();
    homing_in_progress_ = false;
    estop_ = true;
    enabled_ = false;
}

void WtecGripper::set_motor_enabled(bool enable, Clock::time_point now) {
    advance(now);
    if (enable) {
        if (!estop_) {
            enabled_ = true;
            released_ = false;
        }
        return;
    }
    enabled_ = false;
    released_ = true;
    motion_.reset();
    homing_in_progress_ = false;
}

bool WtecGripper::move_to(std::int32_t target, Clock::time_point now) {
    advance(now);
    gripper_.target = static_cast<std::uint32_t>(target);
    if (!can_move()) return false;
    const auto far_stop = static_cast<std::int64_t>(stroke_);
    Goal goal = Goal::target;
    std::int64_t to = target;
    if (to < home_stop) {
        to = home_stop;
        goal = home_is_open() ? Goal::open_stop : Goal::closed_stop;
    } else if (to > far_stop) {
        to = far_stop;
        goal = home_is_open() ? Goal::closed_stop : Goal::open_stop;
    }
    start_motion(to, goal, speed_from(gripper_.speed), now);
    return true;
}

bool WtecGripper::grip_action(wtec::GripAction action, Clock::time_point now) {
    advance(now);
    if (!can_move()) return false;
    bool grip = action == wtec::GripAction::grip;
    if (action == wtec::GripAction::toggle) grip = !last_action_grip_;
    last_action_grip_ = grip;
    if (grip) {
        start_motion(closed_stop(), Goal::closed_stop, speed_from(gripper_.speed), now);
    } else {
        start_motion(open_stop(), Goal::open_stop, speed_from(release_.speed), now);
    }
    return true;
}

void WtecGripper::calibrate_encoder(Clock::time_point now) {
    advance(now);
    motion_.reset();
    homing_in_progress_ = false;
    homed_ = false;
    homing_failed_ = false;
}

void WtecGripper::start_motion(std::int64_t target, Goal goal, std::int64_t speed,
                               Clock::time_point now) {
    closing_ = home_is_open() ? target > position_ : target < position_;
    motion_meets_object_ = false;
    if (object_ && closing_) {
        // The jaws touch the object when the opening equals its width.
        const std::int64_t width = *object_ * static_cast<std::int64_t>(stroke_) / full_object;
        const std::int64_t contact = home_is_open() ? static_cast<std::int64_t>(stroke_) - width : width;
        const bool between = home_is_open() ? (position_ <= contact && contact < target)
                                            : (position_ >= contact && contact > target);
        if (between) {
            target = contact;
            motion_meets_object_ = true;
        }
    }
    motion_goal_ = goal;
    motion_.emplace(now, position_, target, speed);
}

std::int64_t WtecGripper::speed_from(std::uint8_t speed_byte) const noexcept {
    const std::int64_t speed = 2 * static_cast<std::int64_t>(stroke_) * speed_byte / 0xFF;
    return speed > 0 ? speed : 1;
}

std::int64_t WtecGripper::open_stop() const noexcept {
    return home_is_open() ? home_stop : static_cast<std::int64_t>(stroke_);
}

std::int64_t WtecGripper::closed_stop() const noexcept {
    return home_is_open() ? static_cast<std::int64_t>(stroke_) : home_stop;
}

std::uint8_t WtecGripper::homing_state() const noexcept {
    if (homing_in_progress_) return wtec::homing_state::homing;
    if (homed_) return wtec::homing_state::homed;
    if (homing_failed_) return wtec::homing_state::failed;
    return wtec::homing_state::not_homed;
}

std::uint8_t WtecGripper::grip_state() const noexcept {
    if (!enabled_ || estop_) return wtec::grip_state::motor_released;
    if (homing_in_progress_) return wtec::grip_state::moving;
    // seed 003 table 2.8: 11 = not homed, motor released.
    if (!homed_) return wtec::grip_state::motor_released;
    if (motion_) return wtec::grip_state::moving;
    return outcome_;
}

std::uint8_t WtecGripper::current() const noexcept {
    if (!enabled_) return 0;
    if (motion_) return closing_ ? grip_current() : release_.current;
    if (homed_ && outcome_ == wtec::grip_state::gripped) return grip_current();
    return rest_current;
}

void WtecGripper::set_force_percent(std::uint16_t percent) noexcept {
    const std::int64_t current = rounded_div(std::int64_t{percent} * driver_.max_current, 100);
    gripper_.max_current = static_cast<std::uint8_t>(current > 0xFF ? 0xFF : current);
}

std::uint16_t WtecGripper::force_percent() const noexcept {
    // seed 003 table 2.5: the max running current set over ASCII is the 100 % current.
    if (driver_.max_current == 0) return 100;
    const std::int64_t percent = rounded_div(std::int64_t{gripper_.max_current} * 100, driver_.max_current);
    return static_cast<std::uint16_t>(percent > 100 ? 100 : percent);
}

void WtecGripper::set_speed_percent(std::uint16_t percent) noexcept {
    gripper_.speed = static_cast<std::uint8_t>(rounded_div(std::int64_t{percent} * 0xFF, 100));
}

std::uint16_t WtecGripper::speed_percent() const noexcept {
    const std::int64_t percent = rounded_div(std::int64_t{gripper_.speed} * 100, 0xFF);
    return static_cast<std::uint16_t>(percent < 1 ? 1 : percent);
}

void WtecGripper::set_init_direction(std::uint16_t direction) noexcept {
    homing_.mode = direction == 2 ? homing_mode_closed : homing_mode_open;
}

std::uint16_t WtecGripper::init_direction() const noexcept {
    return homing_.mode == homing_mode_closed ? 2 : 1;
}

void WtecGripper::clear_faults() noexcept {
    fail_next_homing_ = false;
    homing_failed_ = false;
}

void WtecGripper::set_position(std::int32_t counts, Clock::time_point now) {
    advance(now);
    motion_.reset();
    position_ = counts;
}

}  // namespace fieldbridge::sim

namespace fieldbridge::sim {

std::string wtec_control(WtecGripper& gripper, std::string_view type, std::string_view command,
                         Clock::time_point now) {
    gripper.advance(now);
    const auto words = split_words(command);
    const std::string name(type);
    if (words.size() == 1 && words[0] == "estop") {
        gripper.emergency_stop(now);
        return {};
    }
    if (words.size() == 1 && words[0] == "fail-homing") {
        gripper.fail_next_homing();
        return {};
    }
    if (words.size() == 1 && words[0] == "clear") {
        gripper.clear_faults();
        return {};
    }
    if (words.size() == 2 && words[0] == "object") {
        if (words[1] == "none") {
            gripper.place_object(std::nullopt);
            return {};
        }
        const auto width = parse_fixed(words[1], 2);
        if (!width || *width < 0 || *width > 10000) {
            return name + ": object width must be 0-100 (percent of the full opening, at most 2 "
                          "decimals) or \"none\", got \"" + std::string(words[1]) + "\"";
        }
        gripper.place_object(*width);
        return {};
    }
    if (words.size() == 2 && words[0] == "position") {
        const auto counts = parse_integer(words[1]);
        if (!counts || *counts < -1000 || *counts > std::int64_t{gripper.stroke()} + 1000) {
            return name + ": position must be encoder counts within the stroke (0-" +
                   std::to_string(gripper.stroke()) + ", +-1000), got \"" + std::string(words[1]) + "\"";
        }
        gripper.set_position(static_cast<std::int32_t>(*counts), now);
        return {};
    }
    return unknown_control(type, command,
                           "estop, object <percent>|none, fail-homing, clear, position <counts>");
}

}  // namespace fieldbridge::sim
