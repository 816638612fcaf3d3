#include "engine/profiles/wtec_ascii_profile.hpp"

#include <algorithm>
#include <array>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>

#include "engine/profiles/builtin_map.hpp"
#include "engine/profiles/wtec_ascii_image.hpp"
#include "protocol/gateway_exceptions.hpp"
#include "engine/profiles/wtec_common.hpp"

namespace fieldbridge::engine {

namespace {

using namespace wtec_reg;
namespace wtec = protocol::wtec;
using protocol::ExceptionCode;

constexpr std::uint8_t homing_mode_reverse = 0xFC;
constexpr std::uint8_t homing_mode_forward = 0xFD;

/// The readable commands, in the order an on-demand read sends them.
enum Source : unsigned { src_I = 0, src_d, src_g, src_N, src_R, src_B, src_P, src_W, src_A, src_count };

[[nodiscard]] wtec::Command command_of(Source s) {
    switch (s) {
        case src_I: return wtec::ReadRunning{};
        case src_d: return wtec::QueryGripState{};
        case src_g: return wtec::QueryHoming{};
        case src_N: return wtec::ReadGripper{};
        case src_R: return wtec::ReadDriver{};
        case src_B: return wtec::ReadHoming{};
        case src_P: return wtec::ReadPid{};
        case src_W: return wtec::ReadRelease{};
        case src_A:
        case src_count: break;
    }
    return wtec::ReadVersion{};
}

/// Which commands fill @p address (the gateway's own registers need none).
void sources_of(Table table, std::uint16_t address, std::array<bool, src_count>& need) {
    if (table == Table::holding) {
        switch (address) {
            case force: need[src_N] = need[src_R] = true; break;
            case speed:
            case position: need[src_N] = true; break;
            case init_state: need[src_g] = true; break;
            case grip_state: need[src_d] = true; break;
            case instant_position: need[src_I] = true; break;
            case init_direction: need[src_B] = true; break;
            default: break;  // estop (latched here), device_id (configured address)
        }
        return;
    }
    if (address < ext_grip_code) {
        need[src_I] = true;
    } else if (address == ext_grip_code) {
        need[src_d] = true;
    } else if (address == ext_homing_code) {
        need[src_g] = true;
    } else if (address < ext_r_max_speed) {
        need[src_N] = true;
    } else if (address < ext_b_mode) {
        need[src_R] = true;
    } else if (address < ext_pid) {
        need[src_B] = true;
    } else if (address < ext_release) {
        need[src_P] = true;
    } else if (address < ext_firmware) {
        need[src_W] = true;
    } else {
        need[src_A] = true;
    }
}

[[nodiscard]] const std::array<core::FunctionCode, 4>& view_functions() {
    // Reads of both tables, writes of single and multiple holding registers.
    static constexpr std::array<core::FunctionCode, 4> functions{
        protocol::fn::read_holding_registers, protocol::fn::read_input_registers,
        protocol::fn::write_single_register, protocol::fn::write_multiple_registers};
    return functions;
}

[[nodiscard]] PollItem poll_item(wtec::Command command, PollClass poll_class, Duration period, bool motion,
                                 std::vector<RegisterSpan> fills) {
    PollItem item;
    item.payload = AsciiPayload{std::move(command)};
    item.poll_class = poll_class;
    item.period = period;
    item.motion = motion;
    item.fills = std::move(fills);
    return item;
}

[[nodiscard]] protocol::Response exception_reply(core::FunctionCode function, ExceptionCode code) {
    return protocol::exception_response(function, code);
}

}  // namespace

std::uint32_t wtec_percent_to_raw(std::uint16_t percent, std::uint32_t full) noexcept {
    const std::uint64_t p = std::min<std::uint16_t>(percent, 100);
    return static_cast<std::uint32_t>((p * full + 99) / 100);
}

std::uint16_t wtec_raw_to_percent(std::int64_t raw, std::uint32_t full) noexcept {
    if (full == 0 || raw <= 0) {
        return 0;
    }
    if (raw > std::int64_t{full}) {
        return 100;
    }
    const auto r = static_cast<std::uint64_t>(raw);
    // Smallest p with ceil(p * full / 100) >= raw.
    const auto candidate = static_cast<std::uint16_t>(100 * (r - 1) / full + 1);
    if (wtec_percent_to_raw(candidate, full) == r) {
        return candidate;
    }
    return static_cast<std::uint16_t>((200 * r + full) / (2 * std::uint64_t{full}));  // nearest
}

std::uint16_t wtec_force_percent(std::uint32_t current, std::uint32_t full) noexcept {
    if (full == 0) {
        return 0;
    }
    const std::uint64_t percent = (std::uint64_t{current} * 100 + full / 2) / full;
    return static_cast<std::uint16_t>(std::min<std::uint64_t>(percent, 100));
}

std::uint32_t wtec_force_current(std::uint16_t percent, std::uint32_t full) noexcept {
    const std::uint64_t p = std::min<std::uint16_t>(percent, 100);
    return static_cast<std::uint32_t>((p * full + 50) / 100);
}

std::uint16_t wtec_uniform_grip_state(std::uint8_t code) noexcept {
    switch (code) {
        case wtec::grip_state::released_to_limit:
        case wtec::grip_state::closed_without_object: return grip_reached;
        case wtec::grip_state::motor_released: return grip_released;
        default: return code;  // 00, 01, 02 are the same numbers; others as they are
    }
}

std::uint16_t wtec_uniform_init_state(std::uint8_t code) noexcept {
    return code == wtec::homing_state::beyond_limit ? init_failed : code;
}

WtecAsciiProfile::WtecAsciiProfile(const ProfileOptions& options)
    : map_(*builtin_register_map(DeviceType::wtec_ascii, options)),
      options_(options),
      state_(builtin_state_points(DeviceType::wtec_ascii, options)) {
    if (!options.wtec_stroke || *options.wtec_stroke == 0) {
        throw ProfileError("wtec-ascii device: `stroke` (encoder counts from the homing point to 100 %) is "
                           "required and must be positive; read N's target at both ends to find it");
    }
    if (*options.wtec_stroke > 0x7FFF'FFFFU) {
        throw ProfileError("wtec-ascii device: `stroke` must be at most 2147483647 (a signed 32-bit `D` target)");
    }
    stroke_ = *options.wtec_stroke;
}

std::optional<ExceptionCode> WtecAsciiProfile::validate(const protocol::Request& request,
                                                        const RegisterImage& image) const {
    if (auto bad = validate_request(map_, request, view_functions(), options_.allow_protected, nullptr)) {
        return bad;
    }
    const std::optional<RequestSpan> span = request_span(request);
    if (!span || !span->write) {
        return std::nullopt;
    }
    for (const WrittenUnit& u : written_units(map_, *span)) {
        const bool known = u.address == force            ? wtec_image::max_current_in(image).has_value()
                           : u.address == speed          ? wtec_image::gripper_in(image).has_value()
                           : u.address == init_direction ? wtec_image::homing_in(image).has_value()
                                                         : true;
        if (!known) {
            // The translation needs R / N / B from the device, not read yet.
            return ExceptionCode::gateway_target_failed;
        }
    }
    return std::nullopt;
}

Classification WtecAsciiProfile::classify(const protocol::Request& request) const {
    return classify_request(map_, request);
}

std::vector<Payload> WtecAsciiProfile::to_line(const protocol::Request& request, const RegisterImage& image) const {
    std::vector<Payload> out;
    const std::optional<RequestSpan> span = request_span(request);
    if (!span) {
        return out;
    }
    if (!span->write) {
        std::array<bool, src_count> need{};
        for (std::size_t a = span->address; a < std::size_t{span->address} + span->count; ++a) {
            sources_of(span->table, static_cast<std::uint16_t>(a), need);
        }
        if (std::none_of(need.begin(), need.end(), [](bool b) { return b; })) {
            need[src_I] = true;  // only gateway registers: ask the device it is there
        }
        for (unsigned s = 0; s < src_count; ++s) {
            if (need[s]) {
                out.push_back(AsciiPayload{command_of(static_cast<Source>(s))});
            }
        }
        return out;
    }
    // Writes: one command per register, in order; N and B as they will be after the
    // earlier commands of the same request.
    std::optional<wtec::GripperParams> n = wtec_image::gripper_in(image);
    const std::optional<wtec::HomingParams> b = wtec_image::homing_in(image);
    const std::uint8_t full_current = wtec_image::max_current_in(image).value_or(0);
    for (std::size_t i = 0; i < span->values.size(); ++i) {
        const auto address = static_cast<std::uint16_t>(span->address + i);
        const std::uint16_t value = span->values[i];
        switch (address) {
            case initialize:
                // Enable the motor first: after an e-stop (`a0`) it stays released
                // until `a1` (seed 003 command 3), and a released gripper does not
                // execute `D` or `E`. The RTU mode's initialise unlocks an e-stop by
                // itself (table 2.12); this makes the view do the same.
                out.push_back(AsciiPayload{wtec::SetMotorEnable{true}});
                out.push_back(AsciiPayload{wtec::Home{}});
                break;
            case estop: out.push_back(AsciiPayload{wtec::SetMotorEnable{false}}); break;
            case force: {
                const auto current = static_cast<std::uint8_t>(wtec_force_current(value, full_current));
                out.push_back(AsciiPayload{wtec::SetPeakCurrent{current}});
                if (n) {
                    n->max_current = current;
                }
                break;
            }
            case speed: {
                wtec::GripperParams params = n.value_or(wtec::GripperParams{});
                params.speed = static_cast<std::uint8_t>(wtec_percent_to_raw(value, 0xFF));
                n = params;
                out.push_back(AsciiPayload{wtec::WriteGripper{params}});
                break;
            }
            case position: {
                const auto target = static_cast<std::int32_t>(wtec_percent_to_raw(value, stroke_));
                out.push_back(AsciiPayload{wtec::SetTarget{target}});  // N's target stays
                break;
            }
            case init_direction: {
                wtec::HomingParams params = b.value_or(wtec::HomingParams{});
                params.mode = value == direction_open ? homing_mode_reverse : homing_mode_forward;
                out.push_back(AsciiPayload{wtec::WriteHoming{params}});
                break;
            }
            case save: out.push_back(AsciiPayload{wtec::SaveAll{}}); break;
            case device_id: out.push_back(AsciiPayload{wtec::SetAddress{static_cast<std::uint8_t>(value)}}); break;
            default: break;  // validate() refuses every other address
        }
    }
    return out;
}

PollPlan WtecAsciiProfile::poll_plan() const {
    const PollPeriods& p = options_.poll;
    std::vector<PollItem> items;
    // Fast: `I` carries position, current, enable and the grip state (same codes as
    // `d`), so `d` is only sent for on-demand reads; `g` for the init state.
    items.push_back(poll_item(wtec::ReadRunning{}, PollClass::fast, p.fast, true,
                              {{Table::holding, grip_state, 1},
                               {Table::holding, instant_position, 1},
                               {Table::holding, estop, 1},
                               {Table::holding, device_id, 1},
                               {Table::input, ext_position, 5}}));
    items.push_back(poll_item(wtec::QueryHoming{}, PollClass::fast, p.fast, true,
                              {{Table::holding, init_state, 1}, {Table::input, ext_homing_code, 1}}));
    items.push_back(poll_item(wtec::ReadGripper{}, PollClass::slow, p.slow, false,
                              {{Table::holding, force, 3}, {Table::input, ext_n_target, 6}}));
    items.push_back(poll_item(wtec::ReadDriver{}, PollClass::slow, p.slow, false,
                              {{Table::holding, force, 1}, {Table::input, ext_r_max_speed, 12}}));
    items.push_back(poll_item(wtec::ReadHoming{}, PollClass::slow, p.slow, false,
                              {{Table::holding, init_direction, 1}, {Table::input, ext_b_mode, 13}}));
    items.push_back(poll_item(wtec::ReadVersion{}, PollClass::startup, Duration{}, false,
                              {{Table::input, ext_firmware, ext_firmware_registers}}));
    items.push_back(poll_item(wtec::ReadPid{}, PollClass::startup, Duration{}, false, {{Table::input, ext_pid, 3}}));
    items.push_back(
        poll_item(wtec::ReadRelease{}, PollClass::startup, Duration{}, false, {{Table::input, ext_release, 2}}));
    return PollPlan{std::move(items)};
}

void WtecAsciiProfile::refresh_gateway_registers(RegisterImage& image, TimePoint now) const {
    // The e-stop latch lives here: 0 when the gateway starts (it cannot know about
    // an earlier `a0`), refreshed with every answer so reads of it stay fresh.
    const std::uint16_t latch = image.value(Table::holding, estop).value_or(0);
    const std::uint16_t id = image.value(Table::holding, device_id).value_or(options_.address.value);
    image.update(Table::holding, estop, std::array<std::uint16_t, 1>{latch}, now);
    image.update(Table::holding, device_id, std::array<std::uint16_t, 1>{id}, now);
}

bool WtecAsciiProfile::apply_reply(const wtec::Command& command, const wtec::Reply& reply, RegisterImage& image,
                                   TimePoint now) const {
    const auto* ack = std::get_if<wtec::Ack>(&reply);
    const auto set_latch = [&image, now](std::uint16_t v) {
        image.update(Table::holding, estop, std::array<std::uint16_t, 1>{v}, now);
    };
    return std::visit(
        [&](const auto& c) -> bool {
            using C = std::decay_t<decltype(c)>;
            if constexpr (std::is_same_v<C, wtec::ReadRunning>) {
                const auto* v = std::get_if<wtec::RunningValues>(&reply);
                return v != nullptr && (wtec_image::store_running(image, *v, stroke_, now), true);
            } else if constexpr (std::is_same_v<C, wtec::QueryGripState>) {
                const auto* v = std::get_if<wtec::StateCode>(&reply);
                return v != nullptr && (wtec_image::store_grip_code(image, v->code, now), true);
            } else if constexpr (std::is_same_v<C, wtec::QueryHoming>) {
                const auto* v = std::get_if<wtec::StateCode>(&reply);
                return v != nullptr && (wtec_image::store_homing_code(image, v->code, now), true);
            } else if constexpr (std::is_same_v<C, wtec::ReadGripper>) {
                const auto* v = std::get_if<wtec::GripperParams>(&reply);
                return v != nullptr && (wtec_image::store_gripper(image, *v, stroke_, now), true);
            } else if constexpr (std::is_same_v<C, wtec::ReadDriver>) {
                const auto* v = std::get_if<wtec::DriverParams>(&reply);
                return v != nullptr && (wtec_image::store_driver(image, *v, now), true);
            } else if constexpr (std::is_same_v<C, wtec::ReadHoming>) {
                const auto* v = std::get_if<wtec::HomingParams>(&reply);
                return v != nullptr && (wtec_image::store_homing(image, *v, now), true);
            } else if constexpr (std::is_same_v<C, wtec::ReadVersion>) {
                const auto* v = std::get_if<wtec::Version>(&reply);
                return v != nullptr && (wtec_image::store_version(image, v->text, now), true);
            } else if constexpr (std::is_same_v<C, wtec::ReadPid>) {
                const auto* v = std::get_if<wtec::Pid>(&reply);
                return v != nullptr && (wtec_image::store_pid(image, *v, now), true);
            } else if constexpr (std::is_same_v<C, wtec::ReadRelease>) {
                const auto* v = std::get_if<wtec::ReleaseParams>(&reply);
                return v != nullptr && (wtec_image::store_release(image, *v, now), true);
            } else if constexpr (std::is_same_v<C, wtec::Home>) {
                // Table 2.12: the e-stop is released only by initialising.
                return ack != nullptr && (set_latch(0), true);
            } else if constexpr (std::is_same_v<C, wtec::SetMotorEnable>) {
                return ack != nullptr && (c.enable || (set_latch(1), true));
            } else if constexpr (std::is_same_v<C, wtec::SetPeakCurrent>) {
                return ack != nullptr && (wtec_image::store_peak_current(image, c.current, now), true);
            } else if constexpr (std::is_same_v<C, wtec::WriteGripper>) {
                return ack != nullptr && (wtec_image::store_gripper(image, c.params, stroke_, now), true);
            } else if constexpr (std::is_same_v<C, wtec::SetTarget>) {
                return ack != nullptr && (wtec_image::store_target(image, c.target, stroke_, now), true);
            } else if constexpr (std::is_same_v<C, wtec::WriteHoming>) {
                return ack != nullptr && (wtec_image::store_homing(image, c.params, now), true);
            } else if constexpr (std::is_same_v<C, wtec::SetAddress>) {
                return ack != nullptr && (image.update(Table::holding, device_id,
                                                       std::array<std::uint16_t, 1>{c.new_address}, now),
                                          true);
            } else if constexpr (std::is_same_v<C, wtec::SaveAll>) {
                return ack != nullptr;
            } else {
                return false;  // commands the view never sends
            }
        },
        command);
}

ApplyResult WtecAsciiProfile::apply(const Payload& sent, const Reply& reply, RegisterImage& image,
                                    TimePoint now) const {
    ApplyResult result;
    const auto* payload = std::get_if<AsciiPayload>(&sent);
    const auto* answer = std::get_if<wtec::Reply>(&reply);
    if (payload == nullptr || answer == nullptr) {
        result.status = ApplyStatus::not_applicable;
        return result;
    }
    if (std::holds_alternative<wtec::NotExecuted>(*answer)) {
        // Seed 003 command 9: the gripper echoed the command and did nothing. A
        // refusal, not a lost reply: answered 0x04 (respond()), never a timeout.
        result.status = ApplyStatus::device_exception;
        result.exception = ExceptionCode::server_device_failure;
        result.notice = DeviceNotice{
            0, std::string{"the gripper did not execute `"} + wtec::letter_of(payload->command) +
                   "` (it echoed the command back): its motor is released or it is not homed; initialise it "
                   "(0x0100 = 1, MQTT op init), which enables the motor and homes"};
        return result;
    }
    if (!apply_reply(payload->command, *answer, image, now)) {
        result.status = ApplyStatus::not_applicable;
        return result;
    }
    refresh_gateway_registers(image, now);
    return result;
}

protocol::Response WtecAsciiProfile::respond(const protocol::Request& request, std::span<const Reply> replies,
                                             const RegisterImage& image) const {
    const core::FunctionCode function = protocol::function_code(request);
    const std::optional<RequestSpan> span = request_span(request);
    if (!span || replies.empty() || replies.size() != to_line(request, image).size()) {
        return exception_reply(function, ExceptionCode::gateway_target_failed);
    }
    for (const Reply& reply : replies) {
        const auto* answer = std::get_if<wtec::Reply>(&reply);
        if (answer != nullptr && std::holds_alternative<wtec::NotExecuted>(*answer)) {
            return exception_reply(function, ExceptionCode::server_device_failure);  // refused: see apply()
        }
        if (answer == nullptr) {
            return exception_reply(function, ExceptionCode::gateway_target_failed);
        }
        if (span->write && !std::holds_alternative<wtec::Ack>(*answer)) {
            return exception_reply(function, ExceptionCode::gateway_target_failed);
        }
    }
    if (span->write) {
        if (const auto* single = std::get_if<protocol::WriteSingleRegisterRequest>(&request)) {
            return protocol::WriteSingleResponse{protocol::fc::write_single_register, single->address, single->value};
        }
        return protocol::WriteMultipleResponse{function.value, span->address, span->count};
    }
    std::vector<std::uint16_t> values;
    values.reserve(span->count);
    for (std::size_t a = span->address; a < std::size_t{span->address} + span->count; ++a) {
        const auto v = image.value(span->table, static_cast<std::uint16_t>(a));
        if (!v) {
            return exception_reply(function, ExceptionCode::gateway_target_failed);
        }
        values.push_back(*v);
    }
    return protocol::ReadRegistersResponse{function.value, std::move(values)};
}

bool WtecAsciiProfile::in_motion(const RegisterImage& image) const {
    return wtec_in_motion(image);
}

DecodedState WtecAsciiProfile::decode_state(const RegisterImage& image) const { return state_.decode(image); }

std::vector<Alarm> WtecAsciiProfile::alarms(const RegisterImage& image) const { return state_.alarms(image); }

OperationSet WtecAsciiProfile::operations() const { return wtec_operations(); }

}  // namespace fieldbridge::engine
