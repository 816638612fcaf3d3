#include "engine/profiles/excd_profile.hpp"

#include <string>
#include <utility>
#include <vector>

#include "engine/profiles/builtin_map.hpp"

namespace fieldbridge::engine {

namespace {

using protocol::ExceptionCode;

// Seed 002 §4 "定義說明". Positions and jogs span 0xFF815A20-0x007EA5E0.
constexpr std::int64_t position_min = -8'300'000;
constexpr std::int64_t position_max = 8'300'000;

// Motion commands ("運轉指令").
constexpr std::uint16_t excd_abs = 0x0100;
constexpr std::uint16_t excd_rel = 0x0104;
constexpr std::uint16_t excd_home = 0x0107;
constexpr std::uint16_t excd_stop = 0x0108;
constexpr std::uint16_t excd_mstop = 0x0109;
constexpr std::uint16_t jog = 0x010A;
constexpr std::uint16_t excd_jog_stop = 0x010C;
constexpr std::uint16_t rby = 0x0205;  // 0 busy, 1 not busy
constexpr std::uint16_t ver = 0x0207;
constexpr std::uint16_t renc = 0x02D4;  // renc, then ralarm 0x02D6

[[nodiscard]] WireFunctions excd_wire_functions() {
    // Seed 002 §2: FC03, FC06, FC10 only.
    return WireFunctions{{protocol::fn::read_holding_registers, protocol::fn::write_single_register,
                          protocol::fn::write_multiple_registers},
                         false, false};
}

// ---- MQTT operations (docs/mqtt.md, "excd203mb") --------------------------------

[[nodiscard]] OperationField excd_pulses(std::string_view name) { return {name, IntegerField{position_min, position_max}}; }

[[nodiscard]] const std::vector<Operation>& excd_operation_table() {
    static const std::vector<Operation> table{
        {"abs", {excd_pulses("position")},
         [](const OperationArgs& a, RegisterValues) {
             return write_multiple(excd_abs, high_word_first(a.integer("position")));
         }},
        {"rel", {excd_pulses("distance")},
         [](const OperationArgs& a, RegisterValues) {
             return write_multiple(excd_rel, high_word_first(a.integer("distance")));
         }},
        {"home", {}, [](const OperationArgs&, RegisterValues) { return write_single(excd_home, 0); }},
        // stop decelerates; mstop (immediate) stops at once.
        {"stop", {{"immediate", BooleanField{}, true}},
         [](const OperationArgs& a, RegisterValues) {
             const bool immediate = a.has("immediate") && a.boolean("immediate");
             return write_single(immediate ? excd_mstop : excd_stop, 0);
         }},
        // Seed 002 "Jog": +1 / -1 is one step, +/-8,300,000 runs until jog stop.
        {"jog",
         {{"direction", ChoiceField{{"forward", "reverse"}}}, {"mode", ChoiceField{{"inch", "continuous"}}}},
         [](const OperationArgs& a, RegisterValues) {
             const std::int64_t magnitude = a.choice("mode") == "continuous" ? position_max : 1;
             return write_multiple(jog, high_word_first(a.choice("direction") == "forward" ? magnitude : -magnitude));
         }},
        {"jog_stop", {}, [](const OperationArgs&, RegisterValues) { return write_single(excd_jog_stop, 0); }},
    };
    return table;
}

}  // namespace

IdentificationRead excd_identification() noexcept { return IdentificationRead{ver, 2}; }

OperationSet excd_operations() { return OperationSet{"excd", excd_operation_table()}; }

ExcdProfile::ExcdProfile(const ProfileOptions& options)
    : ModbusProfile(builtin_register_map(DeviceType::excd203mb, options), excd_wire_functions(), options,
                    options.word_order),
      state_(builtin_state_points(DeviceType::excd203mb, options)) {}

std::optional<ExceptionCode> ExcdProfile::check_value(const RegisterDef& /*def*/, std::uint16_t unit_address,
                                                      std::int64_t value, const RegisterImage& /*image*/) const {
    if (unit_address == jog) {
        // Seed 002 "Jog": +1 / -1 step, or continuous forward / reverse (0x007EA5E0 /
        // 0xFF815A20); the manual lists no other value.
        const bool listed = value == 1 || value == -1 || value == position_max || value == position_min;
        return listed ? std::nullopt : std::optional<ExceptionCode>{ExceptionCode::illegal_data_value};
    }
    return std::nullopt;
}

std::vector<PollUnit> ExcdProfile::poll_units() const {
    std::vector<PollUnit> units;
    const auto add = [&units](std::vector<PollUnit> more) { units.insert(units.end(), more.begin(), more.end()); };
    // Spec §5: status 0x0200-0x020A (rms .. rsa, one block) and renc / ralarm fast;
    // both carry what a motion changes, so both follow the motion period.
    add(units_for(Table::holding, 0x0200, 11, PollClass::fast, true));
    add(units_for(Table::holding, renc, 3, PollClass::fast, true));
    // The system parameters every model has (0x0000-0x0031), slowly: TCP reads of
    // them are then served from the image. The -E only block is not polled.
    add(units_for(Table::holding, 0x0000, 0x32, PollClass::slow));
    return units;
}

bool ExcdProfile::in_motion(const RegisterImage& image) const {
    return image.value(Table::holding, rby) == 0;
}

DecodedState ExcdProfile::decode_state(const RegisterImage& image) const {
    return state_.decode(image);
}

std::vector<Alarm> ExcdProfile::alarms(const RegisterImage& image) const {
    return state_.alarms(image);
}

}  // namespace fieldbridge::engine
