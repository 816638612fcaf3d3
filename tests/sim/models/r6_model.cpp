#include "models/r6_model.hpp"

#include <chrono>

#include "models/control_words.hpp"
#include "models/modbus_request.hpp"

namespace fieldbridge::sim {
namespace {

using protocol::ExceptionCode;
namespace fc = protocol::fc;

// seed 004 3.1.2 example.
constexpr std::string_view version_text = "AM8-QC-RXE-7.8.02-bate7_FAKE_TGF_ENCODER";
constexpr std::uint16_t command_first = 0x4E20;
constexpr std::uint16_t command_last = 0x4E26;
constexpr std::uint16_t coil_count = 0x0120;  // Y, M, EUY: 0x0000-0x011F (seed 004 section 5)
constexpr std::int64_t sweep_speed = 10'000;  // axis 0: 10 deg/s at 100 % global speed
constexpr std::int64_t amplitude_0 = 30'000;  // axis i sweeps 0 .. 30 + 10 i degrees
constexpr std::int64_t ns_per_second = 1'000'000'000;
constexpr std::int64_t ns_per_ms = 1'000'000;

std::int64_t amplitude(std::size_t axis) noexcept {
    return amplitude_0 + 10'000 * static_cast<std::int64_t>(axis);
}

}  // namespace

R6Model::R6Model() : version_(version_text), parameters_(parameter_count, 0) {
    // seed 004 3.1.3 / 3.1.4: two counters, IDs 0 and 1; ID 1 has target 0x0a, current 0x05.
    counters_ = {{0, 100, 0}, {1, 0x0A, 0x05}};
}

std::int32_t R6Model::axis_position(std::size_t axis) const noexcept {
    return axis < max_axes ? axes_[axis] : 0;
}

protocol::Bytes R6Model::handle_pdu(protocol::ByteView request_pdu, Clock::time_point now) {
    advance(now);
    if (request_pdu.empty()) {
        return protocol::encode_exception(0, ExceptionCode::illegal_function);
    }
    const std::uint8_t function = request_pdu[0];
    // seed 004 sections 4 and 5: functions 0x01, 0x03, 0x04, 0x05, 0x06, 0x10.
    if (function != fc::read_coils && function != fc::read_holding_registers &&
        function != fc::read_input_registers && function != fc::write_single_coil &&
        function != fc::write_single_register && function != fc::write_multiple_registers) {
        return protocol::encode_exception(function, ExceptionCode::illegal_function);
    }
    const auto decoded = decode_or_exception(request_pdu);
    if (const auto* error = std::get_if<protocol::Response>(&decoded)) {
        return malformed(request_pdu, protocol::encode_response(*error));
    }
    return malformed(request_pdu, protocol::encode_response(dispatch(std::get<protocol::Request>(decoded))));
}

protocol::Bytes R6Model::malformed(protocol::ByteView request_pdu, protocol::Bytes reply) const {
    if (malform_ == Malform::off || request_pdu.size() < 3 || protocol::get_u16_be(request_pdu, 1) != malform_address_) {
        return reply;
    }
    const std::uint8_t function = request_pdu[0];
    switch (malform_) {
        case Malform::long_exception:  // an exception PDU is 2 bytes
            return {static_cast<std::uint8_t>(function | fc::exception_flag), 0x02, 0x00, 0x00};
        case Malform::extra_registers: {  // 100 registers, whatever was asked
            protocol::Bytes out{function, 200};
            out.resize(202, 0x11);
            return out;
        }
        case Malform::byte_count:  // announces 250 bytes, carries 2
            return {function, 250, 0x00, 0x01};
        case Malform::off: break;
    }
    return reply;
}

protocol::Response R6Model::dispatch(const protocol::Request& request) {
    if (const auto* bits = std::get_if<protocol::ReadBitsRequest>(&request)) return read_coils(*bits);
    if (const auto* regs = std::get_if<protocol::ReadRegistersRequest>(&request)) return read_registers(*regs);
    if (const auto* coil = std::get_if<protocol::WriteSingleCoilRequest>(&request)) return write_coil(*coil);
    if (const auto* single = std::get_if<protocol::WriteSingleRegisterRequest>(&request)) {
        return write_single(*single);
    }
    return write_registers(std::get<protocol::WriteMultipleRegistersRequest>(request));
}

protocol::Response R6Model::read_registers(const protocol::ReadRegistersRequest& request) const {
    protocol::ReadRegistersResponse response{request.function, {}};
    std::uint32_t a = request.address;
    const std::uint32_t end = a + request.count;
    while (a < end) {
        const auto words = a <= 0xFFFF ? read_element(static_cast<std::uint16_t>(a)) : std::nullopt;
        // Unknown, not the start of a value, or a value the count cuts in half: 02.
        if (!words || a + words->size() > end) {
            return exception_of(request.function, ExceptionCode::illegal_data_address);
        }
        response.values.insert(response.values.end(), words->begin(), words->end());
        a += static_cast<std::uint32_t>(words->size());
    }
    return response;
}

protocol::Response R6Model::write_registers(const protocol::WriteMultipleRegistersRequest& request) {
    std::vector<ElementWrite> writes;
    std::size_t i = 0;
    while (i < request.values.size()) {
        const std::uint32_t a = std::uint32_t{request.address} + static_cast<std::uint32_t>(i);
        const std::size_t width = a <= 0xFFFF ? writable_width(static_cast<std::uint16_t>(a),
                                                               request.values.size() - i)
                                              : 0;
        if (width == 0 || i + width > request.values.size()) {
            return exception_of(fc::write_multiple_registers, ExceptionCode::illegal_data_address);
        }
        const auto first = request.values.begin() + static_cast<std::ptrdiff_t>(i);
        writes.push_back({static_cast<std::uint16_t>(a),
                          std::vector<std::uint16_t>(first, first + static_cast<std::ptrdiff_t>(width))});
        i += width;
    }
    for (const auto& w : writes) {
        if (const auto error = check_write(w)) return exception_of(fc::write_multiple_registers, *error);
    }
    for (const auto& w : writes) apply_write(w);
    return protocol::WriteMultipleResponse{fc::write_multiple_registers, request.address,
                                           static_cast<std::uint16_t>(request.values.size())};
}

protocol::Response R6Model::write_single(const protocol::WriteSingleRegisterRequest& request) {
    const protocol::WriteSingleResponse echo{fc::write_single_register, request.address, request.value};
    // seed 004 3.2.1: any value 0-0xFFFF runs the command; commands take FC06 only.
    if (request.address >= command_first && request.address <= command_last) {
        run_command(request.address);
        return echo;
    }
    if (writable_width(request.address, 1) != 1) {
        return exception_of(fc::write_single_register, ExceptionCode::illegal_data_address);
    }
    const ElementWrite w{request.address, {request.value}};
    if (const auto error = check_write(w)) return exception_of(fc::write_single_register, *error);
    apply_write(w);
    return echo;
}

protocol::Response R6Model::read_coils(const protocol::ReadBitsRequest& request) const {
    if (std::uint32_t{request.address} + request.count > coil_count) {
        return exception_of(fc::read_coils, ExceptionCode::illegal_data_address);
    }
    protocol::ReadBitsResponse response{fc::read_coils, {}};
    for (std::uint32_t c = request.address; c < std::uint32_t{request.address} + request.count; ++c) {
        response.bits.push_back(((outputs_[c / 32] >> (c % 32)) & 1u) != 0);
    }
    return response;
}

protocol::Response R6Model::write_coil(const protocol::WriteSingleCoilRequest& request) {
    if (request.address >= coil_count) {
        return exception_of(fc::write_single_coil, ExceptionCode::illegal_data_address);
    }
    const std::uint32_t bit = std::uint32_t{1} << (request.address % 32);
    auto& word = outputs_[request.address / 32];
    word = request.value ? (word | bit) : (word & ~bit);
    return protocol::WriteSingleResponse{fc::write_single_coil, request.address,
                                         static_cast<std::uint16_t>(request.value ? 0xFF00 : 0x0000)};
}

void R6Model::run_command(std::uint16_t address) {
    switch (address) {
        case 0x4E20:  // stop at once; the next start begins the cycle again (the timer)
            moving_ = false;
            cycle_elapsed_ns_ = 0;
            cycle_ms_ = 0;
            break;
        case 0x4E21:  // pause; the next start continues from the current step
        case 0x4E24:  // stop button
            moving_ = false;
            break;
        case 0x4E22:  // single cycle: stop at the end of the current cycle
            single_cycle_ = true;
            break;
        case 0x4E23:  // start button
            start();
            break;
        default:  // 0x4E25 / 0x4E26: clear the alarm and go on when in auto mode
            alarm_ = 0;
            if (mode_ == 2) start();
            break;
    }
}

void R6Model::start() {
    if (alarm_ != 0 || !origin_set_) return;  // a robot in alarm or without origins stays put
    mode_ = 2;
    moving_ = true;
}

R6Model::Counter* R6Model::find_counter(std::uint32_t id) noexcept {
    for (auto& c : counters_) {
        if (c.id == id) return &c;
    }
    return nullptr;
}

const R6Model::Counter* R6Model::find_counter(std::uint32_t id) const noexcept {
    for (const auto& c : counters_) {
        if (c.id == id) return &c;
    }
    return nullptr;
}

void R6Model::advance(Clock::time_point now) {
    if (!clock_started_) {
        clock_started_ = true;
        last_advance_ = now;
        return;
    }
    if (now <= last_advance_) return;
    Clock::duration elapsed = now - last_advance_;
    last_advance_ = now;
    // Step at most an hour at a time so that speed x nanoseconds stays far from overflow.
    constexpr Clock::duration max_step = std::chrono::hours(1);
    while (moving_ && elapsed > Clock::duration::zero()) {
        const Clock::duration step = elapsed < max_step ? elapsed : max_step;
        step_motion(step);
        elapsed -= step;
    }
}

void R6Model::step_motion(Clock::duration elapsed) {
    const std::int64_t speed = sweep_speed * global_speed_ / 1000;
    std::int64_t ns = std::chrono::duration_cast<std::chrono::nanoseconds>(elapsed).count();
    if (speed == 0) {
        cycle_elapsed_ns_ += ns;
        cycle_ms_ = static_cast<std::uint64_t>(cycle_elapsed_ns_ / ns_per_ms);
        return;
    }
    const std::int64_t period = 2 * amplitude_0;
    while (ns > 0 && moving_) {
        // Time to the end of the cycle, in ns, from the current phase.
        const std::int64_t to_end_units = period - phase_;
        const std::int64_t to_end_ns =
            (to_end_units * ns_per_second - phase_remainder_ + speed - 1) / speed;
        if (ns < to_end_ns) {
            const std::int64_t total = phase_remainder_ + speed * ns;
            phase_ += total / ns_per_second;
            phase_remainder_ = total % ns_per_second;
            cycle_elapsed_ns_ += ns;
            ns = 0;
        } else {
            ns -= to_end_ns;
            complete_cycle(cycle_elapsed_ns_ + to_end_ns);
        }
    }
    cycle_ms_ = static_cast<std::uint64_t>(cycle_elapsed_ns_ / ns_per_ms);
    const std::int64_t triangle = phase_ <= amplitude_0 ? phase_ : period - phase_;
    for (std::size_t i = 0; i < max_axes; ++i) {
        axes_[i] = i < axis_count_ ? static_cast<std::int32_t>(triangle * amplitude(i) / amplitude_0) : 0;
    }
}

void R6Model::complete_cycle(std::int64_t cycle_ns) {
    phase_ = 0;
    phase_remainder_ = 0;
    cycle_elapsed_ns_ = 0;
    last_cycle_ms_ = static_cast<std::uint64_t>(cycle_ns / ns_per_ms);
    if (Counter* cycles = find_counter(0)) ++cycles->current;
    if (single_cycle_) {
        single_cycle_ = false;
        moving_ = false;
    }
}

std::string R6Model::control(std::string_view command, Clock::time_point now) {
    advance(now);
    const auto words = split_words(command);
    const auto arg = [&](std::size_t i) { return i < words.size() ? parse_integer(words[i]) : std::nullopt; };
    const auto error = [&](std::string_view what) {
        return "r6: " + std::string(what) + ", got \"" + std::string(command) + "\"";
    };
    if (words.size() == 1 && words[0] == "start") {
        if (alarm_ != 0) return "r6: cannot start while alarm " + std::to_string(alarm_) + " is set; \"clear\" first";
        if (!origin_set_) return "r6: cannot start without origins; \"origin 1\" first";
        start();
        return {};
    }
    if (words.size() == 1 && words[0] == "stop") {
        moving_ = false;
        return {};
    }
    if (words.size() == 1 && words[0] == "clear") {
        alarm_ = 0;
        return {};
    }
    if (words.size() == 2 && words[0] == "alarm") {
        const auto n = arg(1);
        if (!n || *n < 1 || *n > 0xFFFF) return error("alarm needs a number 1-65535 (e.g. alarm 805)");
        alarm_ = static_cast<std::uint16_t>(*n);
        moving_ = false;  // the robot stops on an alarm
        return {};
    }
    if (words.size() == 2 && words[0] == "mode") {
        const auto n = arg(1);
        if (!n || *n < 0 || *n > 0xFFFF) return error("mode needs a number (1 manual, 2 auto, 3 config)");
        mode_ = static_cast<std::uint16_t>(*n);
        return {};
    }
    if (words.size() == 2 && words[0] == "io_boards") {
        const auto n = arg(1);
        if (!n || *n < 0 || *n > 5) return error("io_boards needs 0-5 (seed 004 3.1.6)");
        io_boards_ = static_cast<std::uint16_t>(*n);
        return {};
    }
    if (words.size() == 2 && words[0] == "axes") {
        const auto n = arg(1);
        if (!n || *n < 0 || *n > static_cast<std::int64_t>(max_axes)) return error("axes needs 0-8");
        axis_count_ = static_cast<std::uint16_t>(*n);
        return {};
    }
    if (words.size() == 2 && words[0] == "origin") {
        const auto n = arg(1);
        if (!n || (*n != 0 && *n != 1)) return error("origin needs 0 or 1");
        origin_set_ = *n == 1;
        return {};
    }
    if (words.size() == 3 && words[0] == "input") {
        const auto board = arg(1);
        const auto value = arg(2);
        if (!board || *board < 0 || *board >= static_cast<std::int64_t>(board_count) || !value ||
            *value < 0 || *value > 0xFFFFFFFF) {
            return error("input needs a board 0-8 and a 32-bit value");
        }
        inputs_[static_cast<std::size_t>(*board)] = static_cast<std::uint32_t>(*value);
        return {};
    }
    if (words.size() >= 2 && words[0] == "malform") {
        static const std::map<std::string_view, Malform> kinds{{"off", Malform::off},
                                                               {"long_exception", Malform::long_exception},
                                                               {"extra_registers", Malform::extra_registers},
                                                               {"byte_count", Malform::byte_count}};
        const auto kind = kinds.find(words[1]);
        const auto address = arg(2);
        if (kind == kinds.end() || (kind->second != Malform::off && (words.size() != 3 || !address || *address < 0 ||
                                                                     *address > 0xFFFF))) {
            return error("malform needs off, or long_exception | extra_registers | byte_count and a register "
                         "address (replies to requests starting there are corrupted)");
        }
        malform_ = kind->second;
        malform_address_ = kind->second == Malform::off ? 0 : static_cast<std::uint16_t>(*address);
        return {};
    }
    return unknown_control("r6", command,
                           "start, stop, alarm <n>, clear, mode <n>, io_boards <n>, axes <n>, "
                           "origin <0|1>, input <board> <value>, malform <kind> <address> | off");
}

}  // namespace fieldbridge::sim
