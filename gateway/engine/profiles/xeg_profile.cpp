#include "engine/profiles/xeg_profile.hpp"

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "engine/profiles/builtin_map.hpp"
#include "engine/profiles/profile_text.hpp"

namespace fieldbridge::engine {

namespace {

using protocol::ExceptionCode;

// Seed 001 §3 "Data Allocation Table".
constexpr std::uint16_t di_first = 0x0000;   // IN1-IN6, START, (unused)
constexpr std::uint16_t do_first = 0x0010;   // POS HOLD BUSY ALM1 ALM2 CHK1 CHK2 CHK3
constexpr std::uint16_t actual_position = 0x0300;   // 0.01 mm
constexpr std::uint16_t status = 0x0301;     // 0-7, §3.2
constexpr std::uint16_t firmware = 0x0303;   // 0x0303-0x0306, §3.2
constexpr std::uint16_t model = 0x0600;
constexpr std::uint16_t xeg_trigger = 0x0601;
constexpr std::uint16_t xeg_reset = 0x0610;
constexpr std::uint16_t xeg_stop = 0x0620;
constexpr std::uint16_t move_position = 0x0630;
constexpr std::uint16_t move_speed = 0x0631;
constexpr std::uint16_t expert_direction = 0x0640;
constexpr std::uint16_t expert_move = 0x0641;
constexpr std::uint16_t expert_speed = 0x0642;
constexpr std::uint16_t hold_stroke = 0x0643;
constexpr std::uint16_t hold_speed = 0x0644;
constexpr std::uint16_t hold_force = 0x0645;

constexpr std::uint16_t status_working = 1;

// Seed 001 §3.4.2: "All electric grippers moving range" (mm, mm/s, %), in register
// units (0.01). The manual's "FXEG-16" row is XEG-16 (0x0A10, §3.3).
constexpr std::array<XegModelLimits, 5> model_table{{
    {0x0A10, "XEG-16", 1600, 6000, 1000, 50},
    {0x0A20, "XEG-32", 3200, 8000, 2000, 40},
    {0x0A21, "XEG-32-PR", 3200, 6000, 1000, 50},
    {0x0A30, "XEG-48", 4800, 8000, 2000, 50},
    {0x0A40, "XEG-64", 6400, 10000, 2000, 40},
}};

[[nodiscard]] WireFunctions xeg_wire_functions() {
    // Seed 001 §4.1 function code table; FC06 is accepted northbound and translated.
    return WireFunctions{{protocol::fn::read_discrete_inputs, protocol::fn::read_holding_registers,
                          protocol::fn::read_input_registers, protocol::fn::write_single_register,
                          protocol::fn::read_exception_status, protocol::fn::write_multiple_registers},
                         true, false};
}

// ---- MQTT operations (docs/mqtt.md, "hiwin-xeg"; seed 001 §3.4) -----------------

/// Any 16-bit register of 0.01 mm (or mm/s); check_value() applies the model's limits.
constexpr double xeg_max_mm = 655.35;

[[nodiscard]] OperationField xeg_mm(std::string_view name) { return {name, NumberField{0.0, xeg_max_mm}}; }

[[nodiscard]] const std::vector<Operation>& xeg_operation_table() {
    static const std::vector<Operation> table{
        {"reset", {}, [](const OperationArgs&, RegisterValues) { return write_single(xeg_reset, 1); }},
        {"stop", {}, [](const OperationArgs&, RegisterValues) { return write_single(xeg_stop, 1); }},
        // Position, speed and the move flag: one FC16 (§3.4.2).
        {"move", {xeg_mm("position_mm"), xeg_mm("speed_mm_s")},
         [](const OperationArgs& a, RegisterValues) {
             return write_multiple(move_position,
                                   {hundredths(a.number("position_mm")), hundredths(a.number("speed_mm_s")), 1});
         }},
        // Expert: direction, stroke, speed, holding stroke and speed, force, flag (§3.4.2).
        {"expert",
         {{"direction", IntegerField{0, 1}}, xeg_mm("stroke_mm"), xeg_mm("speed_mm_s"), xeg_mm("holding_stroke_mm"),
          xeg_mm("holding_speed_mm_s"), {"force_pct", IntegerField{0, 100}}},
         [](const OperationArgs& a, RegisterValues) {
             return write_multiple(expert_direction,
                                   {static_cast<std::uint16_t>(a.integer("direction")), hundredths(a.number("stroke_mm")),
                                    hundredths(a.number("speed_mm_s")), hundredths(a.number("holding_stroke_mm")),
                                    hundredths(a.number("holding_speed_mm_s")),
                                    static_cast<std::uint16_t>(a.integer("force_pct")), 1});
         }},
        {"trigger", {{"index", IntegerField{1, 63}}},
         [](const OperationArgs& a, RegisterValues) {
             return write_single(xeg_trigger, static_cast<std::uint16_t>(a.integer("index")));
         }},
    };
    return table;
}

[[nodiscard]] XegModelLimits limits_in(const RegisterImage& image) {
    if (const auto m = image.value(Table::holding, model)) {
        if (const auto known = xeg_model_limits(*m)) {
            return *known;
        }
    }
    return xeg_widest_limits();
}

}  // namespace

std::optional<XegModelLimits> xeg_model_limits(std::uint16_t value) noexcept {
    for (const XegModelLimits& l : model_table) {
        if (l.model == value) {
            return l;
        }
    }
    return std::nullopt;
}

IdentificationRead xeg_identification() noexcept { return IdentificationRead{model, 1}; }

XegModelLimits xeg_widest_limits() noexcept {
    return XegModelLimits{0, "unknown", 6400, 10000, 2000, 40};
}

std::string_view xeg_exception_status_text(std::uint8_t code) noexcept {
    // Seed 001 §4.2.4 "Exception Status Code".
    switch (code) {
        case 0x00: return "no error";
        case 0x02: return "emergency stop";
        case 0x03: return "no command for this address";
        case 0x04: return "incorrect gripper type";
        case 0x05: return "incorrect reset";
        case 0x06: return "incorrect stop";
        case 0x07: return "incorrect move";
        case 0x08: return "incorrect expert";
        case 0x10: return "move error";
        case 0x11: return "move error (over range)";
        case 0x12: return "reset error";
        default: return "exception status not in the manual";
    }
}

OperationSet xeg_operations() { return OperationSet{"xeg", xeg_operation_table()}; }

XegProfile::XegProfile(const ProfileOptions& options)
    : ModbusProfile(builtin_register_map(DeviceType::hiwin_xeg, options), xeg_wire_functions(), options,
                    WordOrder::high_first),
      state_(builtin_state_points(DeviceType::hiwin_xeg, options)) {}

std::optional<ExceptionCode> XegProfile::check_value(const RegisterDef& /*def*/, std::uint16_t unit_address,
                                                     std::int64_t value, const RegisterImage& image) const {
    const XegModelLimits l = limits_in(image);
    bool ok = true;
    switch (unit_address) {
        case model: ok = xeg_model_limits(static_cast<std::uint16_t>(value)).has_value(); break;
        case move_position:
        case expert_move:
        case hold_stroke: ok = value <= l.stroke; break;
        case move_speed:
        case expert_speed: ok = value <= l.speed; break;
        case hold_speed: ok = value <= l.hold_speed; break;
        case hold_force: ok = value >= l.force_min; break;
        default: break;
    }
    return ok ? std::nullopt : std::optional<ExceptionCode>{ExceptionCode::illegal_data_value};
}

std::vector<PollUnit> XegProfile::poll_units() const {
    std::vector<PollUnit> units;
    const auto add = [&units](std::vector<PollUnit> more) { units.insert(units.end(), more.begin(), more.end()); };
    // Spec §5: model and firmware at start, status fast, I/O slower.
    add(units_for(Table::holding, model, 1, PollClass::startup));
    add(units_for(Table::input, firmware, 4, PollClass::startup));
    add(units_for(Table::input, actual_position, 2, PollClass::fast, true));
    // 0x0008-0x000F is a hole: two FC02 reads, never one across it.
    add(units_for(Table::discrete_inputs, di_first, 8, PollClass::slow));
    add(units_for(Table::discrete_inputs, do_first, 8, PollClass::slow));
    return units;
}

void XegProfile::on_device_exception(const protocol::Request& /*sent*/, ExceptionCode code,
                                     ApplyResult& result) const {
    // Seed 001 §4.2.4 / §5: after exception 04 read the exception status (FC07).
    if (code == ExceptionCode::server_device_failure) {
        result.follow_up = ModbusPayload{protocol::ReadExceptionStatusRequest{}};
    }
}

ApplyResult XegProfile::apply(const Payload& sent, const Reply& reply, RegisterImage& image, TimePoint now) const {
    ApplyResult result = ModbusProfile::apply(sent, reply, image, now);
    const auto* payload = std::get_if<ModbusPayload>(&sent);
    if (result.status != ApplyStatus::applied || payload == nullptr || result.follow_up) {
        return result;
    }
    // An acknowledged model write is already in the image (the ranges of the new
    // model apply from the next request on); read it back as Appendix 1 does
    // (scenario 3), so the image holds what the controller took.
    const std::optional<RequestSpan> span = request_span(payload->request);
    if (span && span->write && span->table == Table::holding && span->address <= model &&
        std::size_t{span->address} + span->count > model) {
        result.follow_up =
            ModbusPayload{protocol::ReadRegistersRequest{protocol::fc::read_holding_registers, model, 1}};
    }
    return result;
}

void XegProfile::apply_other(const protocol::Request& sent, const protocol::Response& reply,
                             RegisterImage& /*image*/, TimePoint /*now*/, ApplyResult& result) const {
    const auto* status_reply = std::get_if<protocol::ReadExceptionStatusResponse>(&reply);
    if (!std::holds_alternative<protocol::ReadExceptionStatusRequest>(sent) || status_reply == nullptr) {
        result.status = ApplyStatus::not_applicable;
        return;
    }
    // 0x00 is "no error": nothing to tell an operator (a client's own FC07 read).
    if (status_reply->status == 0) {
        return;
    }
    result.notice = DeviceNotice{status_reply->status,
                                 "exception status " + hex_byte(status_reply->status) + ": " +
                                     std::string{xeg_exception_status_text(status_reply->status)}};
}

bool XegProfile::in_motion(const RegisterImage& image) const {
    return image.value(Table::input, status) == status_working;
}

DecodedState XegProfile::decode_state(const RegisterImage& image) const { return state_.decode(image); }

std::vector<Alarm> XegProfile::alarms(const RegisterImage& image) const { return state_.alarms(image); }

}  // namespace fieldbridge::engine
