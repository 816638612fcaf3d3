#include "models/wtec_rtu_model.hpp"

#include <stdexcept>
#include <string>

#include "models/modbus_request.hpp"
#include "protocol/rtu_frame.hpp"

namespace fieldbridge::sim {
namespace {

using protocol::ExceptionCode;
namespace fc = protocol::fc;
namespace wtec = protocol::wtec;

// seed 003 part 2, table 2.2.
constexpr std::uint16_t reg_init = 0x0100;
constexpr std::uint16_t reg_estop = 0x0102;
constexpr std::uint16_t reg_force = 0x0103;
constexpr std::uint16_t reg_speed = 0x0104;
constexpr std::uint16_t reg_position_command = 0x0105;
constexpr std::uint16_t reg_init_state = 0x0200;
constexpr std::uint16_t reg_grip_state = 0x0202;
constexpr std::uint16_t reg_instant_position = 0x0204;
constexpr std::uint16_t reg_init_direction = 0x0300;
constexpr std::uint16_t reg_save = 0x0302;
constexpr std::uint16_t reg_device_id = 0x0303;
constexpr std::uint8_t max_modbus_address = 247;  // Modbus over Serial Line 2.2

bool in_block(std::uint16_t address) noexcept {
    return (address >= 0x0100 && address <= 0x0105) || (address >= 0x0200 && address <= 0x0205) ||
           (address >= 0x0300 && address <= 0x0303);
}

}  // namespace

std::uint16_t wtec_init_state_register(std::uint8_t homing_code) noexcept {
    switch (homing_code) {
        case wtec::homing_state::homed: return 1;
        case wtec::homing_state::failed:
        case wtec::homing_state::beyond_limit: return 2;
        case wtec::homing_state::homing: return 9;
        default: return 0;
    }
}

std::uint16_t wtec_grip_state_register(std::uint8_t grip_code) noexcept {
    switch (grip_code) {
        case wtec::grip_state::moving: return 0;
        case wtec::grip_state::gripped: return 2;
        case wtec::grip_state::motor_released: return 11;
        default: return 1;  // reached, released to limit, closed to limit: stopped, no object
    }
}

std::uint16_t wtec_percent_of(std::int64_t counts, std::uint32_t stroke) noexcept {
    if (stroke == 0 || counts <= 0) return 0;
    const std::int64_t percent = (counts * 100 + stroke / 2) / stroke;
    return static_cast<std::uint16_t>(percent > 100 ? 100 : percent);
}

WtecRtuModel::WtecRtuModel(std::uint8_t address, std::uint32_t stroke)
    : address_(address), gripper_(stroke) {
    if (address < 1 || address > max_modbus_address) {
        throw std::invalid_argument("wtec-rtu: address " + std::to_string(address) +
                                    " is outside 1-247 (0 is the broadcast address)");
    }
    if (stroke < WtecGripper::min_stroke || stroke > WtecGripper::max_stroke) {
        throw std::invalid_argument("wtec-rtu: stroke " + std::to_string(stroke) +
                                    " counts is outside 100-10000000");
    }
}

std::optional<protocol::Bytes> WtecRtuModel::on_frame(protocol::ByteView frame, Clock::time_point now) {
    const auto request = accept_rtu(frame, address_, protocol::modbus_broadcast_address);
    if (!request) return std::nullopt;
    gripper_.advance(now);
    const std::uint8_t function = request->pdu[0];
    // seed 003 part 2, 2.1.1: function codes 03 and 06.
    if (function != fc::read_holding_registers && function != fc::write_single_register) {
        return rtu_reply(*request, address_, exception_of(function, ExceptionCode::illegal_function));
    }
    auto decoded = decode_or_exception(request->pdu);
    if (auto* error = std::get_if<protocol::Response>(&decoded)) {
        return rtu_reply(*request, address_, *error);
    }
    const auto& parsed = std::get<protocol::Request>(decoded);
    if (const auto* read_request = std::get_if<protocol::ReadRegistersRequest>(&parsed)) {
        return rtu_reply(*request, address_, read(*read_request));
    }
    const auto response = write(std::get<protocol::WriteSingleRegisterRequest>(parsed), now);
    // The ID change takes effect before the reply: it comes from the new ID (seed 003
    // table 2.11 example: 01 06 03 03 00 05 -> 05 06 03 03 00 05).
    return rtu_reply(*request, address_, response);
}

std::optional<std::uint16_t> WtecRtuModel::register_value(std::uint16_t address) const {
    switch (address) {
        case reg_estop: return gripper_.estop_latched() ? 1 : 0;
        case reg_force: return gripper_.force_percent();
        case reg_speed: return gripper_.speed_percent();
        case reg_position_command:
            return wtec_percent_of(static_cast<std::int32_t>(gripper_.gripper_params().target),
                                   gripper_.stroke());
        case reg_init_state: return wtec_init_state_register(gripper_.homing_state());
        case reg_grip_state: return wtec_grip_state_register(gripper_.grip_state());
        case reg_instant_position: return wtec_percent_of(gripper_.position(), gripper_.stroke());
        case reg_init_direction: return gripper_.init_direction();
        case reg_save: return gripper_.saved() ? 1 : 0;
        case reg_device_id: return address_;
        default: break;
    }
    if (in_block(address)) return 0;
    return std::nullopt;
}

protocol::Response WtecRtuModel::read(const protocol::ReadRegistersRequest& request) const {
    protocol::ReadRegistersResponse response{fc::read_holding_registers, {}};
    for (std::uint32_t a = request.address; a < std::uint32_t{request.address} + request.count; ++a) {
        const auto value = a <= 0xFFFF ? register_value(static_cast<std::uint16_t>(a)) : std::nullopt;
        if (!value) return exception_of(fc::read_holding_registers, ExceptionCode::illegal_data_address);
        response.values.push_back(*value);
    }
    return response;
}

protocol::Response WtecRtuModel::write(const protocol::WriteSingleRegisterRequest& request,
                                       Clock::time_point now) {
    const protocol::WriteSingleResponse echo{fc::write_single_register, request.address, request.value};
    const auto bad_value = exception_of(fc::write_single_register, ExceptionCode::illegal_data_value);
    const std::uint16_t v = request.value;
    switch (request.address) {
        case reg_init:
            if (v != 1) return bad_value;
            gripper_.initialise(now);
            return echo;
        case reg_estop:
            // Table 2.12: only initialization unlocks the e-stop, so 0 is not a value.
            if (v != 1) return bad_value;
            gripper_.emergency_stop(now);
            return echo;
        case reg_force:
            if (v < 20 || v > 100) return bad_value;
            gripper_.set_force_percent(v);
            return echo;
        case reg_speed:
            if (v < 1 || v > 100) return bad_value;
            gripper_.set_speed_percent(v);
            return echo;
        case reg_position_command: {
            if (v > 100) return bad_value;
            const std::int64_t target = (std::int64_t{v} * gripper_.stroke() + 50) / 100;
            if (!gripper_.move_to(static_cast<std::int32_t>(target), now)) {
                return exception_of(fc::write_single_register, ExceptionCode::server_device_failure);
            }
            return echo;
        }
        case reg_init_direction:
            if (v < 1 || v > 2) return bad_value;
            gripper_.set_init_direction(v);
            return echo;
        case reg_save:
            if (v > 1) return bad_value;
            gripper_.set_saved(v == 1);
            return echo;
        case reg_device_id:
            if (v < 1 || v > max_modbus_address) return bad_value;
            address_ = static_cast<std::uint8_t>(v);
            return echo;
        default:
            return exception_of(fc::write_single_register, ExceptionCode::illegal_data_address);
    }
}

std::string WtecRtuModel::control(std::string_view command, Clock::time_point now) {
    return wtec_control(gripper_, type(), command, now);
}

std::unique_ptr<BusDevice> make_wtec_rtu(std::uint8_t address, std::uint32_t stroke) {
    return std::make_unique<WtecRtuModel>(address, stroke);
}

}  // namespace fieldbridge::sim
