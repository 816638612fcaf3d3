#include "engine/profiles/excd_profile.hpp"

#include <limits>
#include <string>
#include <utility>
#include <vector>

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

/// A single register (width 1) or a pair (width 2) of the holding table.
[[nodiscard]] RegisterDef reg(std::uint16_t address, std::string name, std::uint8_t width, Access access,
                              std::int64_t min, std::int64_t max, std::uint16_t count = 1) {
    RegisterDef d;
    d.table = Table::holding;
    d.address = address;
    d.width = width;
    d.count = count;
    d.access = access;
    d.min = min;
    d.max = max;
    d.is_signed = min < 0;
    d.name = std::move(name);
    return d;
}

[[nodiscard]] RegisterDef system(std::uint16_t address, std::string name, std::int64_t min, std::int64_t max,
                                 std::uint8_t width = 1) {
    return reg(address, std::move(name), width, Access::read_write, min, max);
}

[[nodiscard]] RegisterDef flagged(RegisterDef d, bool motion, bool protect, std::optional<std::uint16_t> stop = {}) {
    d.motion = motion;
    d.protect = protect;
    d.stop_value = stop;
    return d;
}

[[nodiscard]] std::shared_ptr<const RegisterMap> excd_register_map() {
    constexpr auto rw = Access::read_write;
    constexpr auto w = Access::write;
    constexpr auto r = Access::read;
    std::vector<RegisterDef> defs{
        // System parameters 0x0000-0x0031 (all models).
        system(0x0000, "hdir", 0, 1),
        system(0x0001, "hvs", 1, 0x1388),
        system(0x0002, "htr", 1, 0x927C0, 2),
        system(0x0004, "hvr", 1, 0x7A120, 2),
        system(0x0006, "hsd", 1, 0xFA),
        system(0x0007, "jvs", 1, 0x1388),
        system(0x0008, "jtr", 1, 0x927C0, 2),
        system(0x000A, "jvr", 1, 0x7A120, 2),
        system(0x000C, "svs", 1, 0x1388),
        system(0x000D, "str", 1, 0x927C0, 2),
        system(0x000F, "svr", 1, 0x7A120, 2),
        system(0x0011, "div", 0xC8, 0xC800),
        system(0x0012, "cur", 0x0A, 0x1E),
        system(0x0013, "solmsw", 0, 2),
        system(0x0014, "solm+", position_min, position_max, 2),
        system(0x0016, "solm-", position_min, position_max, 2),
        system(0x0018, "hty", 0, 1),
        system(0x0019, "lty+", 0, 1),
        system(0x001A, "lty-", 0, 1),
        system(0x001B, "sty", 0, 1),
        system(0x001C, "oclr", 0, 1),
        system(0x001D, "auto", 0, 1),
        system(0x001E, "hold", 0, 1),
        flagged(system(0x001F, "idon", 0, 1), false, true),
        flagged(system(0x0020, "id", 0, 0x3F), false, true),
        system(0x0021, "pulse", 0, 1),
        system(0x0022, "pitch", 1, 0x1869F, 2),
        system(0x0024, "hfset", position_min, position_max, 2),
        system(0x0026, "curdwn", 0, 0x64),
        system(0x0027, "extvr", 0, 1),
        system(0x0028, "htime", 5, 0x64),
        system(0x0029, "intime", 5, 0x64),
        system(0x002A, "stime", 5, 0x64),
        flagged(system(0x002B, "baude", 0x4B0, 0x1C200, 2), false, true),
        system(0x002D, "hmode", 0, 1),
        system(0x002E, "hloop", 1, 0xFA),
        system(0x002F, "ifinbit", 0, 1),
        system(0x0030, "curdwnt", 0x64, 0x36EE80, 2),
        // 0x0032-0x003C: EXCD203MB-E only; a plain EXCD203MB answers 0x02 itself.
        system(0x0032, "mdir", 0, 1),
        system(0x0033, "clr", 0, 0),
        system(0x0034, "encdiv", 0, 0),
        system(0x0035, "enc", 0, 2),
        system(0x0036, "homez", 0, 0x64),
        system(0x0037, "edir", 0, 1),
        system(0x0038, "zty", 0, 1),
        system(0x0039, "curm", 5, 0x1E),
        // mbus switches the controller out of Modbus mode: protected like a baud change.
        flagged(system(0x003A, "mbus", 0, 1), false, true),
        system(0x003B, "make", 1, 0x32),
        system(0x003C, "prr", 0, 0xFF),
        // Motion commands 0x0100-0x010C ("運轉指令"): write-only.
        flagged(reg(excd_abs, "abs", 2, w, position_min, position_max), true, false),
        flagged(reg(0x0102, "sabs", 2, w, position_min, position_max), true, false),
        flagged(reg(excd_rel, "rel", 2, w, position_min, position_max), true, false),
        flagged(reg(0x0106, "start", 1, w, 0, 0), true, false),
        flagged(reg(excd_home, "home", 1, w, 0, 0), true, false),
        flagged(reg(excd_stop, "stop", 1, w, 0, 0), true, false, 0),
        flagged(reg(excd_mstop, "mstop", 1, w, 0, 0), true, false, 0),
        flagged(reg(jog, "jog", 2, w, position_min, position_max), true, false),
        flagged(reg(excd_jog_stop, "jog stop", 1, w, 0, 0), true, false, 0),
        // Queries 0x0200-0x020A ("查詢指令"): read-only.
        reg(0x0200, "rms", 1, r, 0, 0xFFFF),
        reg(rabs, "rabs", 2, r, position_min, position_max),
        reg(rin, "rin", 1, r, 0, 0xFFFF),
        reg(rout, "rout", 1, r, 0, 0xFFFF),
        reg(rby, "rby", 1, r, 0, 1),
        reg(sensor, "sensor", 1, r, 0, 0xFFFF),
        reg(ver, "ver", 2, r, 0, 0xFFFF'FFFF),
        reg(0x0209, "rse", 1, r, 0, 0xFFFF),
        reg(0x020A, "rsa", 1, r, 0, 0xFFFF),
        // Counters: rcount1-50 read, cnt1-50 written ("cnt寫入指令").
        reg(0x020C, "rcount", 2, r, 0, 0xFFFF'FFFF, 50),
        reg(0x0270, "cnt", 2, w, position_min, position_max, 50),
        reg(renc, "renc", 2, r, std::numeric_limits<std::int32_t>::min(), std::numeric_limits<std::int32_t>::max()),
        reg(ralarm, "ralarm", 1, r, 0, 0xFFFF),
        // I/O commands and save ("I/O指令", "其他指令").
        reg(0x0300, "outon", 1, w, 0, 0xF),
        reg(0x0301, "clear", 1, w, 0, 0),
        reg(0x0302, "outoff", 1, w, 0, 0xF),
        flagged(reg(0x0303, "save", 1, w, 0, 0), false, true),
        // Variables n01-n99 and counter resets rstcount1-50.
        reg(0x0401, "n", 2, rw, position_min, position_max, 99),
        reg(0x04C7, "rstcount", 1, w, 0, 0, 50),
    };
    return std::make_shared<const RegisterMap>(std::move(defs));
}

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
    : ModbusProfile(excd_register_map(), excd_wire_functions(), options, options.word_order) {}

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
