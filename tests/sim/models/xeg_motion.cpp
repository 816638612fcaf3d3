// XEG-C2 motion: reset (homing), Move, Expert, indirect data, stop and alarms.
// Positions are the jaw opening in 0.01 mm; speeds in 0.01 mm/s (seed 001 3.4.2).
#include "models/xeg_model.hpp"

namespace fieldbridge::sim {
namespace {

// Reset speed: the manual only says to wait 30 s after a reset (Appendix 1); 10.00 mm/s
// homes the longest model (64 mm) in 6.4 s.
constexpr std::int64_t homing_speed = 1000;
constexpr std::int64_t indirect_data_count = 63;

std::uint8_t alarm_code(XegStatus alarm) noexcept {
    switch (alarm) {
        case XegStatus::position_alarm: return xeg_exception_status::over_error;
        case XegStatus::move_alarm: return xeg_exception_status::move_error;
        case XegStatus::home_alarm: return xeg_exception_status::reset_error;
        case XegStatus::emergency_stop: return xeg_exception_status::emergency_stop;
        default: return xeg_exception_status::idle;
    }
}

bool is_alarm(XegStatus status) noexcept { return static_cast<std::uint16_t>(status) >= 4; }

}  // namespace

void XegModel::advance(Clock::time_point now) {
    if (now < last_advance_) now = last_advance_;  // simulated time never runs back
    last_advance_ = now;
    while (!segments_.empty()) {
        const Segment& current = segments_.front();
        if (!current.motion.done_at(now)) {
            position_ = current.motion.position_at(now);
            return;
        }
        const Segment done = current;
        segments_.erase(segments_.begin());
        position_ = done.motion.to();
        finish(done);
    }
}

void XegModel::enqueue(Leg leg, Clock::time_point start, std::int64_t target, std::int64_t speed) {
    const std::int64_t from = position_;
    Segment segment{leg, LinearMove(start, from, target, speed), false, false};
    // The jaws cannot travel past either end of the stroke.
    if (target < 0 || target > connected_.stroke) {
        target = target < 0 ? 0 : connected_.stroke;
        segment.hits_end = true;
    }
    // Closing onto an object of width w stops the jaws at w.
    if (object_width_ && target < from && *object_width_ <= from && *object_width_ > target) {
        target = *object_width_;
        segment.meets_object = true;
        segment.hits_end = false;
    }
    segment.motion = LinearMove(start, from, target, speed);
    segments_.push_back(segment);
}

void XegModel::finish(const Segment& segment) {
    switch (segment.leg) {
        case Leg::homing:
            homed_ = true;
            status_ = XegStatus::idle;
            exception_status_ = xeg_exception_status::idle;
            return;
        case Leg::move:
            // seed 001 3.4.2: "if there are obstacles in the process, an alarm will be output".
            if (segment.meets_object) {
                raise_alarm(XegStatus::move_alarm);
            } else {
                status_ = XegStatus::positioned;
            }
            return;
        case Leg::expert_fast: {
            if (segment.meets_object) {
                status_ = XegStatus::holding;
                return;
            }
            if (segment.hits_end) {
                raise_alarm(XegStatus::position_alarm);
                return;
            }
            // Then the holding stroke at the holding speed (seed 001 4.2.5 example).
            const std::int64_t hold = expert_[3];
            if (hold == 0) {
                status_ = XegStatus::idle;
                return;
            }
            const std::int64_t target = expert_[0] == 0 ? position_ - hold : position_ + hold;
            enqueue(Leg::expert_hold, segment.motion.end(), target, expert_[4]);
            return;
        }
        case Leg::expert_hold:
            if (segment.meets_object) {
                status_ = XegStatus::holding;
            } else if (segment.hits_end) {
                // "if the stroke exceeds the gripping boundary, an alarm will be output"
                raise_alarm(XegStatus::position_alarm);
            } else {
                // Appendix 1: moved 10, held 5 with nothing between the jaws -> "Idle".
                status_ = XegStatus::idle;
            }
            return;
    }
}

void XegModel::raise_alarm(XegStatus alarm) {
    segments_.clear();
    status_ = alarm;
    exception_status_ = alarm_code(alarm);
}

std::optional<std::uint8_t> XegModel::motion_refusal(std::uint8_t command_code) const noexcept {
    if (is_alarm(status_)) return alarm_code(status_);
    if (model_register_ != connected_.code) return xeg_exception_status::type_null;
    // seed 001 3.4.2: reset first; 4.2.5: the gripper must not be working when sent.
    if (!homed_ || status_ == XegStatus::working) return command_code;
    return std::nullopt;
}

std::optional<std::uint8_t> XegModel::start_reset(Clock::time_point now) {
    if (status_ == XegStatus::emergency_stop) return xeg_exception_status::emergency_stop;
    if (model_register_ != connected_.code) return xeg_exception_status::type_null;
    // A reset clears the motion alarms (4-6) and homes to the open end.
    segments_.clear();
    homed_ = false;
    status_ = XegStatus::working;
    enqueue(Leg::homing, now, connected_.stroke, homing_speed);
    return std::nullopt;
}

std::optional<std::uint8_t> XegModel::start_move(std::int64_t target, std::int64_t speed,
                                                 Clock::time_point now) {
    if (const auto refused = motion_refusal(xeg_exception_status::move_null)) return refused;
    status_ = XegStatus::working;
    enqueue(Leg::move, now, target, speed);
    return std::nullopt;
}

std::optional<std::uint8_t> XegModel::start_expert(Clock::time_point now) {
    if (const auto refused = motion_refusal(xeg_exception_status::expert_null)) return refused;
    // 0x0640 direction: 0 inward (closing), 1 outward; 0x0641 is relative.
    const std::int64_t stroke = expert_[1];
    const std::int64_t target = expert_[0] == 0 ? position_ - stroke : position_ + stroke;
    status_ = XegStatus::working;
    enqueue(Leg::expert_fast, now, target, expert_[2]);
    return std::nullopt;
}

std::optional<std::uint8_t> XegModel::start_indirect(std::uint16_t data, Clock::time_point now) {
    if (const auto refused = motion_refusal(xeg_exception_status::move_null)) return refused;
    const std::int64_t target = spec().stroke * data / indirect_data_count;
    status_ = XegStatus::working;
    enqueue(Leg::move, now, target, spec().max_speed);
    return std::nullopt;
}

void XegModel::stop_motion(Clock::time_point now) {
    advance(now);
    if (segments_.empty()) return;
    segments_.clear();
    // Stopped before the end of its reset the gripper is still not homed.
    status_ = XegStatus::idle;
}

}  // namespace fieldbridge::sim
