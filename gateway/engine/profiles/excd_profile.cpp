#include "engine/profiles/excd_profile.hpp"

#include <string>
#include <utility>
#include <vector>

#include "engine/profiles/builtin_map.hpp"
#include "engine/profiles/profile_text.hpp"

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
constexpr std::uint16_t rabs = 0x0201;
constexpr std::uint16_t rin = 0x0203;
constexpr std::uint16_t rout = 0x0204;
constexpr std::uint16_t rby = 0x0205;  // 0 busy, 1 not busy
constexpr std::uint16_t sensor = 0x0206;
constexpr std::uint16_t ver = 0x0207;
constexpr std::uint16_t renc = 0x02D4;
constexpr std::uint16_t ralarm = 0x02D6;

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

[[nodiscard]] std::optional<std::int64_t> pair_in(const RegisterImage& image, std::uint16_t address, bool is_signed) {
    const auto high = image.value(Table::holding, address);
    const auto low = image.value(Table::holding, static_cast<std::uint16_t>(address + 1));
    if (!high || !low) {
        return std::nullopt;
    }
    return pair_value(*high, *low, is_signed);
}

}  // namespace

IdentificationRead excd_identification() noexcept { return IdentificationRead{ver, 2}; }

OperationSet excd_operations() { return OperationSet{"excd", excd_operation_table()}; }

ExcdProfile::ExcdProfile(const ProfileOptions& options)
    : ModbusProfile(builtin_register_map(DeviceType::excd203mb, options), excd_wire_functions(), options,
                    options.word_order) {}

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
    DecodedState state;
    if (const auto p = pair_in(image, rabs, true)) {
        state.fields.push_back({"position", *p, "pulse"});
    }
    if (const auto e = pair_in(image, renc, true)) {
        state.fields.push_back({"encoder", *e, "count"});
    }
    if (const auto b = image.value(Table::holding, rby)) {
        state.fields.push_back({"busy", *b == 0, ""});
    }
    if (const auto in = image.value(Table::holding, rin)) {
        state.fields.push_back({"inputs", std::int64_t{*in}, ""});
    }
    if (const auto out = image.value(Table::holding, rout)) {
        state.fields.push_back({"outputs", std::int64_t{*out}, ""});
    }
    if (const auto s = image.value(Table::holding, sensor)) {
        state.fields.push_back({"sensor", std::int64_t{*s}, ""});
    }
    if (const auto a = image.value(Table::holding, ralarm)) {
        state.fields.push_back({"alarm_code", std::int64_t{*a}, ""});
    }
    if (const auto v = pair_in(image, ver, false)) {
        // The manual does not say how ver is coded: shown as its hex value.
        const auto raw = static_cast<std::uint32_t>(*v);
        state.fields.push_back(
            {"version", hex_word(static_cast<std::uint16_t>(raw >> 16)) + hex_word(static_cast<std::uint16_t>(raw)).substr(2),
             ""});
    }
    return state;
}

std::vector<Alarm> ExcdProfile::alarms(const RegisterImage& image) const {
    std::vector<Alarm> out;
    if (const auto a = image.value(Table::holding, ralarm); a && *a != 0) {
        out.push_back(Alarm{"alarm", "the controller reports alarm code " + std::to_string(*a) +
                                         " (ralarm 0x02D6); see the EXCD203MB manual and clear it at the controller",
                            Severity::error, "holding 0x02D6"});
    }
    return out;
}

}  // namespace fieldbridge::engine
