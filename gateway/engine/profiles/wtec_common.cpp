#include "engine/profiles/wtec_common.hpp"

#include <string>
#include <utility>
#include <variant>

#include "engine/profiles/profile_text.hpp"

namespace fieldbridge::engine {

namespace {

// ---- MQTT operations (docs/mqtt.md, "wtec-rtu and wtec-ascii") ------------------

/// The position (0x0105) that closes (@p close) or opens the jaws. Position 0 % is the
/// end the gripper homes to (seed 003 table 2.9: direction 1 runs to the maximum
/// opening "as the initial start point", 2 to the minimum closing), so closing is
/// 100 % with direction 1 and 0 % with direction 2.
[[nodiscard]] std::variant<std::uint16_t, StateUnknown> wtec_jaw_position(RegisterValues registers, bool close,
                                                                          std::string_view op) {
    using namespace wtec_reg;
    const auto direction = register_value(registers, Table::holding, init_direction);
    const std::string what = "op '" + std::string(op) + "' needs the gripper's init direction (holding " +
                             hex_word(init_direction) + "), ";
    const std::string instead = "; retry in a few seconds (it is polled every `poll.slow`) or use the 'position' op "
                                "with an explicit percent; nothing was sent";
    if (!direction) {
        return StateUnknown{what + "which was not read from the device yet" + instead};
    }
    if (*direction != direction_open && *direction != direction_close) {
        return StateUnknown{what + "which reads " + std::to_string(*direction) + " (neither 1 open nor 2 close)" +
                            instead};
    }
    const bool zero_is_open = *direction == direction_open;
    return std::uint16_t{close == zero_is_open ? std::uint16_t{100} : std::uint16_t{0}};
}

/// grip / release: the optional force and speed first, then the position that moves
/// the jaws.
[[nodiscard]] OperationWrites wtec_approach(const OperationArgs& a, RegisterValues registers, bool close,
                                            std::string_view op) {
    using namespace wtec_reg;
    const auto target = wtec_jaw_position(registers, close, op);
    if (const auto* unknown = std::get_if<StateUnknown>(&target)) return *unknown;
    std::vector<protocol::Request> out;
    if (a.has("force_pct")) {
        out.emplace_back(protocol::WriteSingleRegisterRequest{force, static_cast<std::uint16_t>(a.integer("force_pct"))});
    }
    if (a.has("speed_pct")) {
        out.emplace_back(protocol::WriteSingleRegisterRequest{speed, static_cast<std::uint16_t>(a.integer("speed_pct"))});
    }
    out.emplace_back(protocol::WriteSingleRegisterRequest{position, std::get<std::uint16_t>(target)});
    return out;
}

// Tables 2.5 (force 20-100 %), 2.7 (speed 1-100 %), 2.6 (position 0-100 %).
constexpr IntegerField wtec_force_range{20, 100};
constexpr IntegerField wtec_speed_range{1, 100};

/// One register set to the op's `percent`.
template <std::uint16_t Address>
[[nodiscard]] OperationWrites wtec_percent(const OperationArgs& a, RegisterValues) {
    return write_single(Address, static_cast<std::uint16_t>(a.integer("percent")));
}

[[nodiscard]] const std::vector<Operation>& wtec_operation_table() {
    using namespace wtec_reg;
    static const std::vector<Operation> table{
        {"init", {}, [](const OperationArgs&, RegisterValues) { return write_single(initialize, 1); }},
        {"grip",
         {{"force_pct", wtec_force_range, true}, {"speed_pct", wtec_speed_range, true}},
         [](const OperationArgs& a, RegisterValues r) { return wtec_approach(a, r, true, "grip"); }},
        {"release",
         {{"force_pct", wtec_force_range, true}, {"speed_pct", wtec_speed_range, true}},
         [](const OperationArgs& a, RegisterValues r) { return wtec_approach(a, r, false, "release"); }},
        {"position", {{"percent", IntegerField{0, 100}}}, wtec_percent<position>},
        {"force", {{"percent", wtec_force_range}}, wtec_percent<force>},
        {"speed", {{"percent", wtec_speed_range}}, wtec_percent<speed>},
        {"estop", {}, [](const OperationArgs&, RegisterValues) { return write_single(estop, 1); }},
    };
    return table;
}

}  // namespace

OperationSet wtec_operations() { return OperationSet{"wtec", wtec_operation_table()}; }

std::span<const FieldSetter> wtec_field_setters() noexcept {
    static constexpr FieldSetter setters[] = {
        {"target_pct", "position", "percent"},
        {"force_pct", "force", "percent"},
        {"speed_pct", "speed", "percent"},
    };
    return setters;
}

std::string_view wtec_init_state_name(std::uint16_t value) noexcept {
    switch (value) {
        case wtec_reg::init_not_done: return "not_initialized";
        case wtec_reg::init_done: return "initialized";
        case wtec_reg::init_failed: return "failed";
        case wtec_reg::init_running: return "initializing";
        default: return "unknown";
    }
}

std::string_view wtec_grip_state_name(std::uint16_t value) noexcept {
    switch (value) {
        case wtec_reg::grip_moving: return "moving";
        case wtec_reg::grip_reached: return "reached";
        case wtec_reg::grip_gripped: return "gripped";
        case wtec_reg::grip_released:
        case wtec_reg::grip_released_hex: return "motor_released";
        default: return "unknown";
    }
}

bool wtec_in_motion(const RegisterImage& image) {
    return image.value(Table::holding, wtec_reg::grip_state) == wtec_reg::grip_moving ||
           image.value(Table::holding, wtec_reg::init_state) == wtec_reg::init_running;
}

void decode_wtec_uniform(const RegisterImage& image, DecodedState& state) {
    using namespace wtec_reg;
    const auto value = [&image](std::uint16_t address) { return image.value(Table::holding, address); };
    if (const auto v = value(init_state)) {
        state.fields.push_back({"init_state", std::string{wtec_init_state_name(*v)}, ""});
        state.fields.push_back({"init_state_code", std::int64_t{*v}, ""});
    }
    if (const auto v = value(grip_state)) {
        state.fields.push_back({"grip_state", std::string{wtec_grip_state_name(*v)}, ""});
        state.fields.push_back({"grip_state_code", std::int64_t{*v}, ""});
    }
    if (const auto v = value(instant_position)) {
        state.fields.push_back({"position_pct", std::int64_t{*v}, "%"});
    }
    if (const auto v = value(position)) {
        state.fields.push_back({"target_pct", std::int64_t{*v}, "%"});
    }
    if (const auto v = value(force)) {
        state.fields.push_back({"force_pct", std::int64_t{*v}, "%"});
    }
    if (const auto v = value(speed)) {
        state.fields.push_back({"speed_pct", std::int64_t{*v}, "%"});
    }
    if (const auto v = value(estop)) {
        state.fields.push_back({"estop", *v != 0, ""});
    }
    if (const auto v = value(init_direction)) {
        const std::string name = *v == direction_open ? "open" : *v == direction_close ? "close" : "unknown";
        state.fields.push_back({"init_direction", name, ""});
    }
}

std::vector<Alarm> wtec_uniform_alarms(const RegisterImage& image, std::optional<std::uint16_t> raw_homing_code) {
    using namespace wtec_reg;
    std::vector<Alarm> out;
    if (image.value(Table::holding, init_state) == init_failed) {
        // Seed 003 command 11: 03 is "超过极限位置" (beyond the limit position),
        // shown as failed (2) in the uniform register.
        if (raw_homing_code == 0x03) {
            out.push_back(Alarm{"beyond_limit", "homing went beyond the limit position; check the stroke and initialise again",
                                Severity::error, "holding 0x0200"});
        } else {
            out.push_back(Alarm{"init_failed", "initialisation (homing) failed; remove any obstacle and initialise again",
                                Severity::error, "holding 0x0200"});
        }
    }
    if (image.value(Table::holding, estop) == 1) {
        out.push_back(Alarm{"emergency_stop", "emergency stop latched; only initialising (0x0100 = 1) releases it",
                            Severity::critical, "holding 0x0102"});
    }
    return out;
}

}  // namespace fieldbridge::engine
