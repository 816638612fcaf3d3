#include "northbound/mqtt/command_parser.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <initializer_list>
#include <set>
#include <utility>

#include "northbound/upstream/r6_map.hpp"

namespace fieldbridge::northbound::mqtt {

namespace {

using nlohmann::json;
using protocol::Request;
using protocol::WriteMultipleRegistersRequest;
using protocol::WriteSingleRegisterRequest;

/// A refusal found while reading the fields; caught by parse_command().
struct Refusal {
    CommandErrorKind kind;
    std::string message;
};

/// Reads the fields of one command object and remembers which were used, so that a
/// field the op does not take is refused (a misspelt field must not be ignored).
class Fields {
public:
    explicit Fields(const json& object) : object_(object) {}

    [[nodiscard]] bool has(const char* name) const { return object_.contains(name); }

    /// A number in [min, max].
    [[nodiscard]] double number(const char* name, double min, double max) {
        const json& value = get(name);
        if (!value.is_number()) {
            throw Refusal{CommandErrorKind::invalid_field, std::string("field '") + name + "' must be a number"};
        }
        const double v = value.get<double>();
        if (!std::isfinite(v) || v < min || v > max) {
            throw Refusal{CommandErrorKind::out_of_range, std::string("field '") + name + "' must be within " +
                                                              format(min) + ".." + format(max)};
        }
        return v;
    }

    /// A number of @p scale units (0.01 mm: scale 100) as a register value.
    [[nodiscard]] std::uint16_t scaled(const char* name, double scale, double max_value) {
        const double v = number(name, 0.0, max_value);
        return static_cast<std::uint16_t>(std::lround(v * scale));
    }

    [[nodiscard]] std::int64_t integer(const char* name, std::int64_t min, std::int64_t max) {
        return integer_of(get(name), name, min, max);
    }

    [[nodiscard]] bool boolean(const char* name) {
        const json& value = get(name);
        if (!value.is_boolean()) {
            throw Refusal{CommandErrorKind::invalid_field, std::string("field '") + name + "' must be true or false"};
        }
        return value.get<bool>();
    }

    [[nodiscard]] std::string choice(const char* name, std::initializer_list<const char*> options) {
        const json& value = get(name);
        std::string list;
        for (const char* o : options) {
            list += list.empty() ? "" : ", ";
            list += std::string("\"") + o + "\"";
        }
        if (value.is_string()) {
            const auto text = value.get<std::string>();
            for (const char* o : options) {
                if (text == o) {
                    return text;
                }
            }
        }
        throw Refusal{value.is_string() ? CommandErrorKind::out_of_range : CommandErrorKind::invalid_field,
                      std::string("field '") + name + "' must be one of " + list};
    }

    [[nodiscard]] std::vector<std::int64_t> integers(const char* name, std::int64_t min, std::int64_t max,
                                                     std::size_t max_count) {
        const json& value = get(name);
        if (!value.is_array() || value.empty()) {
            throw Refusal{CommandErrorKind::invalid_field,
                          std::string("field '") + name + "' must be a non-empty array of integers"};
        }
        if (value.size() > max_count) {
            throw Refusal{CommandErrorKind::out_of_range, std::string("field '") + name + "' holds at most " +
                                                              std::to_string(max_count) + " values"};
        }
        std::vector<std::int64_t> out;
        for (const json& item : value) {
            out.push_back(integer_of(item, name, min, max));
        }
        return out;
    }

    /// Refuses any field that no reader asked for.
    void finish() const {
        for (const auto& [key, value] : object_.items()) {
            if (used_.count(key) == 0) {
                throw Refusal{CommandErrorKind::invalid_field, "field '" + key + "' is not taken by this op"};
            }
        }
    }

private:
    const json& get(const char* name) {
        used_.insert(name);
        const auto it = object_.find(name);
        if (it == object_.end()) {
            throw Refusal{CommandErrorKind::missing_field, std::string("field '") + name + "' is required"};
        }
        return *it;
    }

    static std::string format(double v) {
        json j = v;
        if (v == std::floor(v) && std::fabs(v) < 1e15) {
            j = static_cast<std::int64_t>(v);
        }
        return j.dump();
    }

    static std::int64_t integer_of(const json& value, const char* name, std::int64_t min, std::int64_t max) {
        std::int64_t v = 0;
        if (value.is_number_integer()) {
            v = value.get<std::int64_t>();
        } else if (value.is_number_float() && value.get<double>() == std::floor(value.get<double>()) &&
                   std::fabs(value.get<double>()) < 9e15) {
            v = static_cast<std::int64_t>(value.get<double>());
        } else {
            throw Refusal{CommandErrorKind::invalid_field, std::string("field '") + name + "' must be an integer"};
        }
        if (value.is_number_unsigned() && value.get<std::uint64_t>() > static_cast<std::uint64_t>(max)) {
            v = max + 1;  // beyond int64: out of range below
        }
        if (v < min || v > max) {
            throw Refusal{CommandErrorKind::out_of_range, std::string("field '") + name + "' must be within " +
                                                              std::to_string(min) + ".." + std::to_string(max)};
        }
        return v;
    }

    const json& object_;
    std::set<std::string> used_{"id", "op"};
};

[[nodiscard]] Request single(std::uint16_t address, std::uint16_t value) {
    return WriteSingleRegisterRequest{address, value};
}

[[nodiscard]] Request multiple(std::uint16_t address, std::vector<std::uint16_t> values) {
    return WriteMultipleRegistersRequest{address, std::move(values)};
}

/// A signed 32-bit value as two registers, high word first (the northbound view,
/// docs/registers.md; the profile swaps them for a low-first device).
[[nodiscard]] std::vector<std::uint16_t> pair(std::int64_t value) {
    const auto bits = static_cast<std::uint32_t>(static_cast<std::int32_t>(value));
    return {static_cast<std::uint16_t>(bits >> 16), static_cast<std::uint16_t>(bits & 0xFFFF)};
}

using Op = std::function<std::vector<Request>(Fields&)>;
using OpTable = std::vector<std::pair<std::string_view, Op>>;

// ---- every command set ----------------------------------------------------------

/// set_register {address, value}: one FC06 (the XEG profile sends it as FC16).
std::vector<Request> set_register(Fields& f) {
    const auto address = static_cast<std::uint16_t>(f.integer("address", 0, 0xFFFF));
    const auto value = static_cast<std::uint16_t>(f.integer("value", 0, 0xFFFF));
    return {single(address, value)};
}

/// write_registers {address, values, table?}: holding registers (FC06 for one value,
/// FC16 for more) or coils (FC05 / FC15).
std::vector<Request> write_registers(Fields& f) {
    const auto address = static_cast<std::uint16_t>(f.integer("address", 0, 0xFFFF));
    const std::string table = f.has("table") ? f.choice("table", {"holding", "coils"}) : "holding";
    if (table == "coils") {
        const auto values = f.integers("values", 0, 1, protocol::max_write_coils);
        if (values.size() == 1) {
            return {protocol::WriteSingleCoilRequest{address, values[0] != 0}};
        }
        std::vector<bool> bits;
        for (auto v : values) bits.push_back(v != 0);
        return {protocol::WriteMultipleCoilsRequest{address, std::move(bits)}};
    }
    const auto values = f.integers("values", 0, 0xFFFF, protocol::max_write_registers);
    if (values.size() == 1) {
        return {single(address, static_cast<std::uint16_t>(values[0]))};
    }
    std::vector<std::uint16_t> words;
    for (auto v : values) words.push_back(static_cast<std::uint16_t>(v));
    return {multiple(address, std::move(words))};
}

// ---- HIWIN XEG (seed 001 section 3.4; docs/registers.md) -------------------------

constexpr double xeg_max_mm = 655.35;  // a 16-bit register of 0.01 mm; the profile checks the model's stroke

OpTable xeg_ops() {
    return {
        {"reset", [](Fields&) { return std::vector<Request>{single(0x0610, 1)}; }},
        {"stop", [](Fields&) { return std::vector<Request>{single(0x0620, 1)}; }},
        {"move",
         [](Fields& f) {
             const auto position = f.scaled("position_mm", 100, xeg_max_mm);
             const auto speed = f.scaled("speed_mm_s", 100, xeg_max_mm);
             // 0x0630 position, 0x0631 speed, 0x0632 move flag: one FC16 (section 3.4.2).
             return std::vector<Request>{multiple(0x0630, {position, speed, 1})};
         }},
        {"expert",
         [](Fields& f) {
             const auto direction = static_cast<std::uint16_t>(f.integer("direction", 0, 1));
             const auto stroke = f.scaled("stroke_mm", 100, xeg_max_mm);
             const auto speed = f.scaled("speed_mm_s", 100, xeg_max_mm);
             const auto holding_stroke = f.scaled("holding_stroke_mm", 100, xeg_max_mm);
             const auto holding_speed = f.scaled("holding_speed_mm_s", 100, xeg_max_mm);
             const auto force = static_cast<std::uint16_t>(f.integer("force_pct", 0, 100));
             return std::vector<Request>{
                 multiple(0x0640, {direction, stroke, speed, holding_stroke, holding_speed, force, 1})};
         }},
        {"trigger",
         [](Fields& f) {
             return std::vector<Request>{single(0x0601, static_cast<std::uint16_t>(f.integer("index", 1, 63)))};
         }},
    };
}

// ---- EXCD203MB (seed 002 "運轉指令") --------------------------------------------

constexpr std::int64_t excd_max_position = 8'300'000;

OpTable excd_ops() {
    return {
        {"abs",
         [](Fields& f) {
             return std::vector<Request>{
                 multiple(0x0100, pair(f.integer("position", -excd_max_position, excd_max_position)))};
         }},
        {"rel",
         [](Fields& f) {
             return std::vector<Request>{
                 multiple(0x0104, pair(f.integer("distance", -excd_max_position, excd_max_position)))};
         }},
        {"home", [](Fields&) { return std::vector<Request>{single(0x0107, 0)}; }},
        {"stop",
         [](Fields& f) {
             const bool immediate = f.has("immediate") && f.boolean("immediate");
             return std::vector<Request>{single(immediate ? 0x0109 : 0x0108, 0)};
         }},
        {"jog",
         [](Fields& f) {
             const bool forward = f.choice("direction", {"forward", "reverse"}) == "forward";
             const bool continuous = f.choice("mode", {"inch", "continuous"}) == "continuous";
             const std::int64_t magnitude = continuous ? excd_max_position : 1;
             return std::vector<Request>{multiple(0x010A, pair(forward ? magnitude : -magnitude))};
         }},
        {"jog_stop", [](Fields&) { return std::vector<Request>{single(0x010C, 0)}; }},
    };
}

// ---- WTEC-485, both modes: the uniform map (seed 003 part 2) --------------------

constexpr std::uint16_t wtec_init_direction = 0x0300;  // holding: 1 open, 2 close
constexpr std::uint16_t wtec_direction_open = 1;
constexpr std::uint16_t wtec_direction_close = 2;

/// The position (0x0105) that closes (@p close) or opens the jaws. Position 0 % is the
/// end the gripper homes to (seed 003 table 2.9: direction 1 runs to the maximum
/// opening "as the initial start point", 2 to the minimum closing), so closing is
/// 100 % with direction 1 and 0 % with direction 2.
std::uint16_t wtec_jaw_position(std::span<const RawRegister> registers, bool close, const char* op) {
    const auto it = std::find_if(registers.begin(), registers.end(), [](const RawRegister& r) {
        return r.table == engine::Table::holding && r.address == wtec_init_direction;
    });
    const std::string what = std::string("op '") + op + "' needs the gripper's init direction (holding 0x0300), ";
    const std::string instead = "; retry in a few seconds (it is polled every `poll.slow`) or use the 'position' op "
                                "with an explicit percent; nothing was sent";
    if (it == registers.end()) {
        throw Refusal{CommandErrorKind::state_unknown, what + "which was not read from the device yet" + instead};
    }
    if (it->value != wtec_direction_open && it->value != wtec_direction_close) {
        throw Refusal{CommandErrorKind::state_unknown,
                      what + "which reads " + std::to_string(it->value) + " (neither 1 open nor 2 close)" + instead};
    }
    const bool zero_is_open = it->value == wtec_direction_open;
    return close == zero_is_open ? 100 : 0;
}

OpTable wtec_ops(std::span<const RawRegister> registers) {
    // Optional force / speed first, then the position that moves the jaws.
    const auto approach = [registers](Fields& f, bool close, const char* op) {
        std::vector<Request> out;
        if (f.has("force_pct")) out.push_back(single(0x0103, static_cast<std::uint16_t>(f.integer("force_pct", 20, 100))));
        if (f.has("speed_pct")) out.push_back(single(0x0104, static_cast<std::uint16_t>(f.integer("speed_pct", 1, 100))));
        out.push_back(single(0x0105, wtec_jaw_position(registers, close, op)));
        return out;
    };
    return {
        {"init", [](Fields&) { return std::vector<Request>{single(0x0100, 1)}; }},
        {"grip", [approach](Fields& f) { return approach(f, true, "grip"); }},
        {"release", [approach](Fields& f) { return approach(f, false, "release"); }},
        {"position",
         [](Fields& f) {
             return std::vector<Request>{single(0x0105, static_cast<std::uint16_t>(f.integer("percent", 0, 100)))};
         }},
        {"force",
         [](Fields& f) {
             return std::vector<Request>{single(0x0103, static_cast<std::uint16_t>(f.integer("percent", 20, 100)))};
         }},
        {"speed",
         [](Fields& f) {
             return std::vector<Request>{single(0x0104, static_cast<std::uint16_t>(f.integer("percent", 1, 100)))};
         }},
        {"estop", [](Fields&) { return std::vector<Request>{single(0x0102, 1)}; }},
    };
}

// ---- Huacheng R6 (seed 004 3.2.1, 3.2.2, 3.3.3) ----------------------------------

OpTable r6_ops() {
    return {
        {"stop", [](Fields&) { return std::vector<Request>{single(r6::command_stop, 1)}; }},
        {"pause", [](Fields&) { return std::vector<Request>{single(r6::command_pause, 1)}; }},
        {"start", [](Fields&) { return std::vector<Request>{single(r6::command_start_button, 1)}; }},
        {"clear_alarm",
         [](Fields& f) {
             // 0x4E25 clears and runs the next instruction, 0x4E26 clears and continues
             // the automatic run: both move the robot, so the caller says which.
             const bool next = f.choice("resume", {"next", "continue"}) == "next";
             return std::vector<Request>{single(next ? 0x4E25 : 0x4E26, 1)};
         }},
        {"global_speed",
         [](Fields& f) {
             // 0x4EE8: 0-1000 for 0.0-100.0 %.
             const double percent = f.number("percent", 0.0, 100.0);
             return std::vector<Request>{single(0x4EE8, static_cast<std::uint16_t>(std::lround(percent * 10.0)))};
         }},
        {"output",
         [](Fields& f) {
             // 0x4E58-0x4E5A: board (0-3 IO, 4-6 M, 7 EUIO), point 0-31, state; FC16 only.
             const auto board = static_cast<std::uint16_t>(f.integer("board", 0, 7));
             const auto point = static_cast<std::uint16_t>(f.integer("point", 0, 31));
             const auto on = static_cast<std::uint16_t>(f.boolean("on") ? 1 : 0);
             return std::vector<Request>{multiple(0x4E58, {board, point, on})};
         }},
    };
}

OpTable ops_of(CommandSet set, std::span<const RawRegister> registers) {
    OpTable table;
    switch (set) {
        case CommandSet::xeg: table = xeg_ops(); break;
        case CommandSet::excd: table = excd_ops(); break;
        case CommandSet::wtec: table = wtec_ops(registers); break;
        case CommandSet::r6: table = r6_ops(); break;
        case CommandSet::generic: break;
    }
    table.emplace_back("set_register", set_register);
    table.emplace_back("write_registers", write_registers);
    return table;
}

/// Parses @p payload; @p duplicate names the first key an object holds twice.
/// nlohmann-json keeps the last of duplicate keys, so `{"op":"stop","op":"reset"}`
/// would run `reset` while a log or an audit of the first key reads `stop`: such a
/// command is refused (the parser callback sees every key in document order).
[[nodiscard]] json parse_strict(std::string_view payload, std::string& duplicate) {
    std::vector<std::set<std::string>> open;
    const json::parser_callback_t check = [&](int /*depth*/, json::parse_event_t event, json& parsed) {
        switch (event) {
            case json::parse_event_t::object_start: open.emplace_back(); break;
            case json::parse_event_t::object_end:
                if (!open.empty()) open.pop_back();
                break;
            case json::parse_event_t::key:
                if (!open.empty() && !open.back().insert(parsed.get<std::string>()).second && duplicate.empty()) {
                    duplicate = parsed.get<std::string>();
                }
                break;
            default: break;
        }
        return true;
    };
    return json::parse(payload, check, /*allow_exceptions=*/false);
}

}  // namespace

std::string_view to_string(CommandErrorKind kind) noexcept {
    switch (kind) {
        case CommandErrorKind::bad_json: return "bad_json";
        case CommandErrorKind::missing_id: return "missing_id";
        case CommandErrorKind::unknown_op: return "unknown_op";
        case CommandErrorKind::missing_field: return "missing_field";
        case CommandErrorKind::invalid_field: return "invalid_field";
        case CommandErrorKind::out_of_range: return "out_of_range";
        case CommandErrorKind::state_unknown: return "state_unknown";
    }
    return "unknown";
}

std::vector<std::string_view> command_ops(CommandSet set) {
    std::vector<std::string_view> names;
    for (const auto& [name, op] : ops_of(set, {})) names.push_back(name);
    return names;
}

ParseResult parse_command(std::string_view payload, CommandSet set, std::span<const RawRegister> registers) {
    std::string duplicate;
    const json command = parse_strict(payload, duplicate);
    if (command.is_discarded() || !command.is_object()) {
        return CommandError{CommandErrorKind::bad_json, "the command must be a JSON object", json(), {}};
    }
    if (!duplicate.empty()) {
        // No id echoed either: which of the duplicates would it be?
        return CommandError{CommandErrorKind::bad_json,
                            "key '" + duplicate + "' appears twice in one object; each key may appear once",
                            json(), {}};
    }
    json id;
    if (const auto it = command.find("id"); it != command.end() && (it->is_string() || it->is_number())) {
        id = *it;
    } else {
        return CommandError{CommandErrorKind::missing_id, "field 'id' (a string or a number) is required", json(), {}};
    }
    const auto op_it = command.find("op");
    if (op_it == command.end() || !op_it->is_string()) {
        return CommandError{CommandErrorKind::unknown_op, "field 'op' (a string) is required", id, {}};
    }
    const auto op = op_it->get<std::string>();
    const OpTable table = ops_of(set, registers);
    const auto entry = std::find_if(table.begin(), table.end(), [&](const auto& e) { return e.first == op; });
    if (entry == table.end()) {
        std::string known;
        for (const auto& [name, fn] : table) {
            known += known.empty() ? "" : ", ";
            known += name;
        }
        return CommandError{CommandErrorKind::unknown_op,
                            "op '" + op + "' is not a " + std::string(to_string(set)) + " command (ops: " + known + ")",
                            id, op};
    }
    try {
        Fields fields(command);
        std::vector<Request> requests = entry->second(fields);
        fields.finish();
        return ParsedCommand{id, op, std::move(requests)};
    } catch (const Refusal& refusal) {
        return CommandError{refusal.kind, refusal.message, id, op};
    }
}

}  // namespace fieldbridge::northbound::mqtt
