#include "models/wtec_ascii_model.hpp"

#include <stdexcept>
#include <string>

namespace fieldbridge::sim {
namespace {

namespace wtec = protocol::wtec;

// seed 003 command 1 example: ">01ACstep [A]1.623921".
constexpr std::string_view firmware_version = "Cstep [A]1.62";

/// Runs one decoded command on the gripper; the reply it gets, if any.
struct Executor {
    WtecGripper& gripper;
    std::uint8_t& address;
    Clock::time_point now;

    using Result = wtec::Reply;
    static Result ack() { return wtec::Ack{}; }

    Result operator()(const wtec::ReadVersion&) const { return wtec::Version{std::string(firmware_version)}; }
    Result operator()(const wtec::ReadStations&) const { return wtec::Station{address}; }
    Result operator()(const wtec::SetMotorEnable& c) const {
        gripper.set_motor_enabled(c.enable, now);
        return ack();
    }
    Result operator()(const wtec::ReadHoming&) const { return gripper.homing_params(); }
    Result operator()(const wtec::WriteHoming& c) const {
        gripper.set_homing_params(c.params);
        return ack();
    }
    Result operator()(const wtec::SetPeakCurrent& c) const {
        gripper.set_grip_current(c.current);  // the N max current
        return ack();
    }
    Result operator()(const wtec::SetTarget& c) const {
        // A released motor does not act: the command comes back as it was sent, as
        // seed 003 documents for `E` (command 9, "返回原指令").
        if (gripper.motor_released()) return wtec::NotExecuted{};
        (void)gripper.move_to(c.target, now);  // not homed: the target is only stored
        return ack();
    }
    Result operator()(const wtec::QueryGripState&) const { return wtec::StateCode{gripper.grip_state()}; }
    Result operator()(const wtec::GripperAction& c) const {
        // seed 003 command 9: not homed (or released): echoed, nothing done.
        if (!gripper.grip_action(c.action, now)) return wtec::NotExecuted{};
        return ack();
    }
    Result operator()(const wtec::Home&) const {
        gripper.home(now);
        return ack();
    }
    Result operator()(const wtec::QueryHoming&) const { return wtec::StateCode{gripper.homing_state()}; }
    Result operator()(const wtec::ReadRunning&) const {
        return wtec::RunningValues{gripper.position(), gripper.current(), gripper.enabled(),
                                   gripper.grip_state()};
    }
    Result operator()(const wtec::SetAddress& c) const {
        address = c.new_address;
        return ack();
    }
    Result operator()(const wtec::ReadPid&) const { return gripper.pid(); }
    Result operator()(const wtec::WritePid& c) const {
        gripper.set_pid(c.pid);
        return ack();
    }
    Result operator()(const wtec::ReadGripper&) const { return gripper.gripper_params(); }
    Result operator()(const wtec::WriteGripper& c) const {
        gripper.set_gripper_params(c.params);
        return ack();
    }
    Result operator()(const wtec::ReadDriver&) const { return gripper.driver_params(); }
    Result operator()(const wtec::WriteDriver& c) const {
        gripper.set_driver_params(c.params);
        return ack();
    }
    Result operator()(const wtec::SaveAll&) const {
        gripper.set_saved(true);
        return ack();
    }
    Result operator()(const wtec::ReadRelease&) const { return gripper.release_params(); }
    Result operator()(const wtec::WriteRelease& c) const {
        gripper.set_release_params(c.params);
        return ack();
    }
    Result operator()(const wtec::CalibrateEncoder&) const {
        gripper.calibrate_encoder(now);
        return ack();
    }
};

}  // namespace

WtecAsciiModel::WtecAsciiModel(std::uint8_t address, std::uint32_t stroke)
    : address_(address), gripper_(stroke) {
    if (address < 1 || address > wtec::max_address) {
        throw std::invalid_argument("wtec-ascii: address " + std::to_string(address) +
                                    " is outside 1-253 (0 is the broadcast address)");
    }
    if (stroke < WtecGripper::min_stroke || stroke > WtecGripper::max_stroke) {
        throw std::invalid_argument("wtec-ascii: stroke " + std::to_string(stroke) +
                                    " counts is outside 100-10000000");
    }
}

std::optional<protocol::Bytes> WtecAsciiModel::on_frame(protocol::ByteView frame, Clock::time_point now) {
    const auto scanned = wtec::scan_frame(frame);
    if (!scanned.complete()) return std::nullopt;
    const wtec::AsciiFrame& request = scanned.value;
    const bool broadcast = request.address == wtec::broadcast_address;
    if (!broadcast && request.address != address_) return std::nullopt;
    const auto command = wtec::decode_command(request);
    if (!command.complete()) return std::nullopt;
    gripper_.advance(now);
    const std::uint8_t replying = address_;
    const wtec::Reply reply = std::visit(Executor{gripper_, address_, now}, command.value);
    // seed 003 command 2: "$" to 00 is answered by every device; "00 为广播" otherwise.
    if (broadcast && !std::holds_alternative<wtec::ReadStations>(command.value)) return std::nullopt;
    const std::string text = wtec::encode_frame(wtec::encode_reply(replying, command.value, reply));
    return protocol::Bytes(text.begin(), text.end());
}

std::string WtecAsciiModel::control(std::string_view command, Clock::time_point now) {
    return wtec_control(gripper_, type(), command, now);
}

std::unique_ptr<BusDevice> make_wtec_ascii(std::uint8_t address, std::uint32_t stroke) {
    return std::make_unique<WtecAsciiModel>(address, stroke);
}

}  // namespace fieldbridge::sim
