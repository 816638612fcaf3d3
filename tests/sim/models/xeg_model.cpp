#include "models/xeg_model.hpp"

#include <stdexcept>
#include <string>

#include "models/control_words.hpp"
#include "models/modbus_request.hpp"
#include "protocol/rtu_frame.hpp"

namespace fieldbridge::sim {
namespace {

using protocol::ExceptionCode;
namespace fc = protocol::fc;

// seed 001 section 3 (data allocation table).
constexpr std::uint16_t di_first = 0x0000;
constexpr std::uint16_t di_last = 0x0007;
constexpr std::uint16_t do_first = 0x0010;
constexpr std::uint16_t do_last = 0x0017;
constexpr std::uint16_t reg_current_position = 0x0300;
constexpr std::uint16_t reg_status = 0x0301;
constexpr std::uint16_t reg_firmware = 0x0303;
constexpr std::uint16_t reg_model = 0x0600;
constexpr std::uint16_t reg_trigger = 0x0601;
constexpr std::uint16_t reg_reset = 0x0610;
constexpr std::uint16_t reg_stop = 0x0620;
constexpr std::uint16_t reg_move = 0x0630;       // 0x0630 target, 0x0631 speed, 0x0632 flag
constexpr std::uint16_t reg_move_flag = 0x0632;
constexpr std::uint16_t reg_expert = 0x0640;     // 0x0640-0x0645 parameters, 0x0646 flag
constexpr std::uint16_t reg_expert_flag = 0x0646;

// Appendix 1 reads V3.0.1.884 from 0x0303-0x0306.
constexpr std::array<std::uint16_t, 4> firmware{3, 0, 1, 884};
constexpr std::int64_t max_position = 6400;  // section 3: 0x0300 range 0-6400

constexpr std::array<XegSpec, 5> specs{{
    // code, stroke, max speed, max hold speed, min force (section 3.4.2 table)
    {0x0A10, 1600, 6000, 1000, 50},   // XEG-16
    {0x0A20, 3200, 8000, 2000, 40},   // XEG-32
    {0x0A21, 3200, 6000, 1000, 50},   // XEG-32-PR
    {0x0A30, 4800, 8000, 2000, 50},   // XEG-48
    {0x0A40, 6400, 10000, 2000, 40},  // XEG-64
}};

bool is_holding(std::uint16_t address) noexcept {
    return address == reg_model || address == reg_trigger || address == reg_reset ||
           address == reg_stop || (address >= reg_move && address <= reg_move_flag) ||
           (address >= reg_expert && address <= reg_expert_flag);
}

bool is_input_register(std::uint16_t address) noexcept {
    return address == reg_current_position || address == reg_status ||
           (address >= reg_firmware && address < reg_firmware + firmware.size());
}

bool is_bit(std::uint16_t address) noexcept {
    return address <= di_last || (address >= do_first && address <= do_last);
}

/// True when every address of [first, first + count) satisfies @p exists.
template <typename Pred>
bool all_exist(std::uint16_t first, std::uint16_t count, Pred exists) {
    for (std::uint32_t a = first; a < std::uint32_t{first} + count; ++a) {
        if (a > 0xFFFF || !exists(static_cast<std::uint16_t>(a))) return false;
    }
    return true;
}

}  // namespace

std::optional<XegSpec> xeg_spec(std::uint16_t code) noexcept {
    for (const auto& spec : specs) {
        if (spec.code == code) return spec;
    }
    return std::nullopt;
}

XegModel::XegModel(std::uint8_t address, XegOptions options) : address_(address) {
    // seed 001 section 2.2: IDs 1-F, 0 is the broadcast address.
    if (address < 1 || address > 15) {
        throw std::invalid_argument("hiwin-xeg: address " + std::to_string(address) +
                                    " is outside 1-15 (the controller's ID switch)");
    }
    const auto spec = xeg_spec(options.model);
    if (!spec) {
        throw std::invalid_argument("hiwin-xeg: model code " + std::to_string(options.model) +
                                    " is not one of 0x0A10, 0x0A20, 0x0A21, 0x0A30, 0x0A40");
    }
    connected_ = *spec;
    spec_ = *spec;
    model_register_ = spec->code;
}

std::optional<protocol::Bytes> XegModel::on_frame(protocol::ByteView frame, Clock::time_point now) {
    const auto request = accept_rtu(frame, address_, protocol::modbus_broadcast_address);
    if (!request) return std::nullopt;
    advance(now);
    auto decoded = decode_or_exception(request->pdu);
    if (auto* error = std::get_if<protocol::Response>(&decoded)) {
        // An FC the controller lacks is 01 even when its PDU is also malformed.
        const std::uint8_t function = request->pdu[0];
        const bool known = function == fc::read_discrete_inputs ||
                           function == fc::read_holding_registers ||
                           function == fc::read_input_registers ||
                           function == fc::read_exception_status ||
                           function == fc::write_multiple_registers ||
                           function == fc::write_single_register;
        if (!known) *error = exception_of(function, ExceptionCode::illegal_function);
        return rtu_reply(*request, address_, *error);
    }
    const auto response = handle(std::get<protocol::Request>(decoded), request->broadcast, now);
    return rtu_reply(*request, address_, response);
}

protocol::Response XegModel::handle(const protocol::Request& request, bool broadcast,
                                    Clock::time_point now) {
    const std::uint8_t function = protocol::function_of(request);
    if (const auto* bits = std::get_if<protocol::ReadBitsRequest>(&request)) {
        if (bits->function == fc::read_discrete_inputs) return read_bits(*bits);
    } else if (const auto* regs = std::get_if<protocol::ReadRegistersRequest>(&request)) {
        return regs->function == fc::read_input_registers ? read_input_registers(*regs)
                                                          : read_holding(*regs);
    } else if (std::holds_alternative<protocol::ReadExceptionStatusRequest>(request)) {
        return protocol::ReadExceptionStatusResponse{exception_status_};
    } else if (const auto* write = std::get_if<protocol::WriteMultipleRegistersRequest>(&request)) {
        return write_holding(*write, now);
    } else if (const auto* single = std::get_if<protocol::WriteSingleRegisterRequest>(&request)) {
        // seed 001 section 5: FC06 to 0x0611 (not in the map) answers 02. FC06 is not in
        // the function table (section 4.1), so on an address of the map it is 01.
        return exception_of(function, is_holding(single->address) ? ExceptionCode::illegal_function
                                                                  : ExceptionCode::illegal_data_address);
    }
    (void)broadcast;  // reads to address 0 are processed like any other; nobody answers
    return exception_of(function, ExceptionCode::illegal_function);
}

std::uint8_t XegModel::discrete_bits() const noexcept {
    // seed 001 section 3.1: POS HOLD BUSY ALM1 ALM2 CHK1 CHK2 CHK3 at 0x0010-0x0017.
    std::uint8_t bits = 0;
    switch (status_) {
        case XegStatus::positioned: bits |= 0x01; break;
        case XegStatus::holding: bits |= 0x02; break;
        case XegStatus::working: bits |= 0x04; break;
        case XegStatus::position_alarm:
        case XegStatus::move_alarm:
        case XegStatus::home_alarm: bits |= 0x08; break;
        case XegStatus::emergency_stop: bits |= 0x10; break;
        case XegStatus::idle: break;
    }
    return bits;
}

protocol::Response XegModel::read_bits(const protocol::ReadBitsRequest& request) const {
    if (!all_exist(request.address, request.count, is_bit)) {
        return exception_of(request.function, ExceptionCode::illegal_data_address);
    }
    protocol::ReadBitsResponse response{request.function, {}};
    const std::uint8_t outputs = discrete_bits();
    for (std::uint16_t i = 0; i < request.count; ++i) {
        const auto address = static_cast<std::uint16_t>(request.address + i);
        const bool on = address <= di_last ? ((inputs_ >> (address - di_first)) & 1u) != 0
                                           : ((outputs >> (address - do_first)) & 1u) != 0;
        response.bits.push_back(on);
    }
    return response;
}

protocol::Response XegModel::read_input_registers(const protocol::ReadRegistersRequest& request) const {
    if (!all_exist(request.address, request.count, is_input_register)) {
        return exception_of(request.function, ExceptionCode::illegal_data_address);
    }
    protocol::ReadRegistersResponse response{request.function, {}};
    for (std::uint16_t i = 0; i < request.count; ++i) {
        const auto address = static_cast<std::uint16_t>(request.address + i);
        if (address == reg_current_position) {
            const std::int64_t clamped = position_ < 0 ? 0 : (position_ > max_position ? max_position : position_);
            response.values.push_back(static_cast<std::uint16_t>(clamped));
        } else if (address == reg_status) {
            response.values.push_back(static_cast<std::uint16_t>(status_));
        } else {
            response.values.push_back(firmware[address - reg_firmware]);
        }
    }
    return response;
}

protocol::Response XegModel::read_holding(const protocol::ReadRegistersRequest& request) const {
    if (!all_exist(request.address, request.count, is_holding)) {
        return exception_of(request.function, ExceptionCode::illegal_data_address);
    }
    protocol::ReadRegistersResponse response{request.function, {}};
    for (std::uint16_t i = 0; i < request.count; ++i) {
        const auto address = static_cast<std::uint16_t>(request.address + i);
        std::uint16_t value = 0;  // trigger, reset, stop and both flags auto-reset to 0
        if (address == reg_model) {
            value = model_register_;
        } else if (address == reg_move) {
            value = move_target_;
        } else if (address == reg_move + 1) {
            value = move_speed_;
        } else if (address >= reg_expert && address < reg_expert_flag) {
            value = expert_[address - reg_expert];
        }
        response.values.push_back(value);
    }
    return response;
}

std::optional<protocol::ExceptionCode> XegModel::check_value(std::uint16_t address,
                                                             std::uint16_t value) const {
    // seed 001 section 3 and 3.4.2: ranges per register and per model.
    std::int64_t max = 1;
    switch (address) {
        case reg_model:
            return xeg_spec(value) ? std::nullopt : std::optional{ExceptionCode::illegal_data_value};
        case reg_trigger: max = 63; break;
        case reg_move: max = spec().stroke; break;
        case reg_move + 1: max = spec().max_speed; break;
        case reg_expert + 1: max = spec().stroke; break;
        case reg_expert + 2: max = spec().max_speed; break;
        case reg_expert + 3: max = spec().stroke; break;
        case reg_expert + 4: max = spec().max_hold_speed; break;
        case reg_expert + 5: max = 100; break;  // the model's minimum is checked on the flag
        default: break;                          // reset, stop, direction, flags: 0-1
    }
    return value <= max ? std::nullopt : std::optional{ExceptionCode::illegal_data_value};
}

protocol::Response XegModel::write_holding(const protocol::WriteMultipleRegistersRequest& request,
                                           Clock::time_point now) {
    const auto count = static_cast<std::uint16_t>(request.values.size());
    const protocol::WriteMultipleResponse ok{fc::write_multiple_registers, request.address, count};
    if (!all_exist(request.address, count, is_holding)) {
        return exception_of(fc::write_multiple_registers, ExceptionCode::illegal_data_address);
    }
    bool reset = false;
    bool stop = false;
    bool move = false;
    bool expert = false;
    std::uint16_t trigger = 0;
    for (std::uint16_t i = 0; i < count; ++i) {
        const auto address = static_cast<std::uint16_t>(request.address + i);
        if (const auto error = check_value(address, request.values[i])) {
            return exception_of(fc::write_multiple_registers, *error);
        }
    }
    for (std::uint16_t i = 0; i < count; ++i) {
        const auto address = static_cast<std::uint16_t>(request.address + i);
        const std::uint16_t value = request.values[i];
        if (address == reg_model) {
            model_register_ = value;
            spec_ = *xeg_spec(value);
        } else if (address == reg_trigger) {
            trigger = value;
        } else if (address == reg_reset) {
            reset = value == 1;
        } else if (address == reg_stop) {
            stop = value == 1;
        } else if (address == reg_move) {
            move_target_ = value;
        } else if (address == reg_move + 1) {
            move_speed_ = value;
        } else if (address == reg_move_flag) {
            move = value == 1;
        } else if (address == reg_expert_flag) {
            expert = value == 1;
        } else {
            expert_[address - reg_expert] = value;
        }
    }
    // A motion the gripper cannot make at all is bad data (03); one it cannot make now
    // is a controller error (04) explained by FC07.
    if (move && move_speed_ == 0) {
        return exception_of(fc::write_multiple_registers, ExceptionCode::illegal_data_value);
    }
    if (expert && (expert_[2] == 0 || (expert_[3] > 0 && expert_[4] == 0) ||
                   expert_[5] < spec().min_force)) {
        return exception_of(fc::write_multiple_registers, ExceptionCode::illegal_data_value);
    }
    std::optional<std::uint8_t> refused;
    if (stop) stop_motion(now);
    if (reset) refused = start_reset(now);
    if (!refused && move) refused = start_move(move_target_, move_speed_, now);
    if (!refused && expert) refused = start_expert(now);
    if (!refused && trigger != 0) refused = start_indirect(trigger, now);
    if (refused) {
        exception_status_ = *refused;
        return exception_of(fc::write_multiple_registers, ExceptionCode::server_device_failure);
    }
    return ok;
}

std::string XegModel::control(std::string_view command, Clock::time_point now) {
    advance(now);
    const auto words = split_words(command);
    constexpr std::string_view known = "alarm 4..7, clear, object <mm>|none, inputs <mask>";
    if (words.size() == 2 && words[0] == "alarm") {
        const auto code = parse_integer(words[1]);
        if (!code || *code < 4 || *code > 7) {
            return "hiwin-xeg: alarm must be a status code 4-7 (seed 001 section 3.2), got \"" +
                   std::string(words[1]) + "\"";
        }
        raise_alarm(static_cast<XegStatus>(*code));
        return {};
    }
    if (words.size() == 1 && words[0] == "clear") {
        if (status_ == XegStatus::home_alarm) homed_ = false;
        if (static_cast<std::uint16_t>(status_) >= 4) status_ = XegStatus::idle;
        exception_status_ = xeg_exception_status::idle;
        return {};
    }
    if (words.size() == 2 && words[0] == "object") {
        if (words[1] == "none") {
            object_width_.reset();
            return {};
        }
        const auto width = parse_fixed(words[1], 2);
        if (!width || *width < 0 || *width > connected_.stroke) {
            return "hiwin-xeg: object width must be 0-" + std::to_string(connected_.stroke / 100) +
                   " mm with at most 2 decimals, got \"" + std::string(words[1]) + "\"";
        }
        object_width_ = *width;
        return {};
    }
    if (words.size() == 2 && words[0] == "inputs") {
        const auto mask = parse_integer(words[1]);
        if (!mask || *mask < 0 || *mask > 0x7F) {
            return "hiwin-xeg: inputs must be a mask 0-0x7F of IN1..IN6, START, got \"" +
                   std::string(words[1]) + "\"";
        }
        inputs_ = static_cast<std::uint8_t>(*mask);
        return {};
    }
    return unknown_control("hiwin-xeg", command, known);
}

std::unique_ptr<BusDevice> make_xeg(std::uint8_t address, XegOptions options) {
    return std::make_unique<XegModel>(address, options);
}

}  // namespace fieldbridge::sim
