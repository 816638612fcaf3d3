#include "northbound/mqtt/command_parser.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <set>
#include <utility>

#include "northbound/mqtt/point_commands.hpp"

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

    [[nodiscard]] bool has(const std::string& name) const { return object_.contains(name); }

    /// A number in [min, max].
    [[nodiscard]] double number(const std::string& name, double min, double max) {
        const json& value = get(name);
        if (!value.is_number()) {
            throw Refusal{CommandErrorKind::invalid_field, "field '" + name + "' must be a number"};
        }
        const double v = value.get<double>();
        if (!std::isfinite(v) || v < min || v > max) {
            throw Refusal{CommandErrorKind::out_of_range,
                          "field '" + name + "' must be within " + format(min) + ".." + format(max)};
        }
        return v;
    }

    [[nodiscard]] std::int64_t integer(const std::string& name, std::int64_t min, std::int64_t max) {
        return integer_of(get(name), name, min, max);
    }

    [[nodiscard]] bool boolean(const std::string& name) {
        const json& value = get(name);
        if (!value.is_boolean()) {
            throw Refusal{CommandErrorKind::invalid_field, "field '" + name + "' must be true or false"};
        }
        return value.get<bool>();
    }

    [[nodiscard]] std::string choice(const std::string& name, const std::vector<std::string_view>& options) {
        const json& value = get(name);
        std::string list;
        for (const std::string_view o : options) {
            list += list.empty() ? "" : ", ";
            list += "\"" + std::string(o) + "\"";
        }
        if (value.is_string()) {
            const auto text = value.get<std::string>();
            if (std::find(options.begin(), options.end(), text) != options.end()) {
                return text;
            }
        }
        throw Refusal{value.is_string() ? CommandErrorKind::out_of_range : CommandErrorKind::invalid_field,
                      "field '" + name + "' must be one of " + list};
    }

    [[nodiscard]] std::vector<std::int64_t> integers(const std::string& name, std::int64_t min, std::int64_t max,
                                                     std::size_t max_count) {
        const json& value = get(name);
        if (!value.is_array() || value.empty()) {
            throw Refusal{CommandErrorKind::invalid_field, "field '" + name + "' must be a non-empty array of integers"};
        }
        if (value.size() > max_count) {
            throw Refusal{CommandErrorKind::out_of_range,
                          "field '" + name + "' holds at most " + std::to_string(max_count) + " values"};
        }
        std::vector<std::int64_t> out;
        for (const json& item : value) {
            out.push_back(integer_of(item, name, min, max));
        }
        return out;
    }

    /// Reads @p field as its spec says into @p args (an absent optional field: nothing).
    void read(const engine::OperationField& field, engine::OperationArgs& args) {
        const std::string name(field.name);
        if (field.optional && !has(name)) {
            return;
        }
        if (const auto* n = std::get_if<engine::NumberField>(&field.type)) {
            args.set(field.name, number(name, n->min, n->max));
        } else if (const auto* i = std::get_if<engine::IntegerField>(&field.type)) {
            args.set(field.name, integer(name, i->min, i->max));
        } else if (const auto* c = std::get_if<engine::ChoiceField>(&field.type)) {
            args.set(field.name, choice(name, c->options));
        } else {
            args.set(field.name, boolean(name));
        }
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
    const json& get(const std::string& name) {
        used_.insert(name);
        const auto it = object_.find(name);
        if (it == object_.end()) {
            throw Refusal{CommandErrorKind::missing_field, "field '" + name + "' is required"};
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

    static std::int64_t integer_of(const json& value, const std::string& name, std::int64_t min, std::int64_t max) {
        std::int64_t v = 0;
        if (value.is_number_integer()) {
            v = value.get<std::int64_t>();
        } else if (value.is_number_float() && value.get<double>() == std::floor(value.get<double>()) &&
                   std::fabs(value.get<double>()) < 9e15) {
            v = static_cast<std::int64_t>(value.get<double>());
        } else {
            throw Refusal{CommandErrorKind::invalid_field, "field '" + name + "' must be an integer"};
        }
        if (value.is_number_unsigned() && value.get<std::uint64_t>() > static_cast<std::uint64_t>(max)) {
            v = max + 1;  // beyond int64: out of range below
        }
        if (v < min || v > max) {
            throw Refusal{CommandErrorKind::out_of_range, "field '" + name + "' must be within " +
                                                              std::to_string(min) + ".." + std::to_string(max)};
        }
        return v;
    }

    const json& object_;
    std::set<std::string> used_{"id", "op"};
};

// ---- the raw register ops every device takes (docs/mqtt.md, "Every device type") ----
// The address is the caller's: they hold no device knowledge.

constexpr std::int64_t max_address = std::numeric_limits<std::uint16_t>::max();
constexpr std::int64_t max_register_value = std::numeric_limits<std::uint16_t>::max();

/// set_register {address, value}: one FC06 (the XEG profile sends it as FC16).
std::vector<Request> set_register(Fields& f) {
    const auto address = static_cast<std::uint16_t>(f.integer("address", 0, max_address));
    const auto value = static_cast<std::uint16_t>(f.integer("value", 0, max_register_value));
    return {WriteSingleRegisterRequest{address, value}};
}

/// write_registers {address, values, table?}: holding registers (FC06 for one value,
/// FC16 for more) or coils (FC05 / FC15).
std::vector<Request> write_registers(Fields& f) {
    const auto address = static_cast<std::uint16_t>(f.integer("address", 0, max_address));
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
    const auto values = f.integers("values", 0, max_register_value, protocol::max_write_registers);
    if (values.size() == 1) {
        return {WriteSingleRegisterRequest{address, static_cast<std::uint16_t>(values[0])}};
    }
    std::vector<std::uint16_t> words;
    for (auto v : values) words.push_back(static_cast<std::uint16_t>(v));
    return {WriteMultipleRegistersRequest{address, std::move(words)}};
}

using RawOp = std::vector<Request> (*)(Fields&);
constexpr std::array<std::pair<std::string_view, RawOp>, 2> raw_ops{{
    {"set_register", set_register},
    {"write_registers", write_registers},
}};

/// The requests of a device operation, its fields read from @p f.
std::vector<Request> device_op(Fields& f, const engine::Operation& op, std::span<const RawRegister> registers) {
    engine::OperationArgs args;
    for (const engine::OperationField& field : op.fields) {
        f.read(field, args);
    }
    engine::OperationWrites writes = op.writes(args, registers);
    if (auto* unknown = std::get_if<engine::StateUnknown>(&writes)) {
        throw Refusal{CommandErrorKind::state_unknown, std::move(unknown->message)};
    }
    return std::get<std::vector<Request>>(std::move(writes));
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

/// `write` / `read` of a device with points: only `values` / `points` besides id and op.
ParseResult point_command(const json& command, const json& id, const std::string& op,
                          const core::PointModel& points) {
    const std::string member = op == "write" ? "values" : "points";
    for (const auto& [key, value] : command.items()) {
        if (key != "id" && key != "op" && key != member) {
            return CommandError{CommandErrorKind::invalid_field, "field '" + key + "' is not taken by this op", id, op};
        }
    }
    const auto it = command.find(member);
    const json* given = it == command.end() ? nullptr : &*it;
    PointOp built = op == "write" ? point_write(points, given) : point_read(points, given);
    if (!built.ok()) {
        static constexpr std::array kinds{CommandErrorKind::missing_field, CommandErrorKind::invalid_field,
                                          CommandErrorKind::out_of_range};
        const auto kind = std::find_if(kinds.begin(), kinds.end(), [&](auto k) { return to_string(k) == built.kind; });
        return CommandError{kind == kinds.end() ? CommandErrorKind::invalid_field : *kind, std::move(built.message),
                            id, op};
    }
    return ParsedCommand{id, op, std::move(built.requests), std::move(built.read_points)};
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

std::vector<std::string_view> command_ops(const engine::OperationSet& operations, const core::PointModel* points) {
    std::vector<std::string_view> names;
    for (const engine::Operation& op : operations.operations) names.push_back(op.name);
    if (points != nullptr && takes_point_write(*points)) names.push_back("write");
    if (points != nullptr && takes_point_read(*points)) names.push_back("read");
    for (const auto& [name, op] : raw_ops) names.push_back(name);
    return names;
}

ParseResult parse_command(std::string_view payload, const engine::OperationSet& operations,
                          std::span<const RawRegister> registers, const core::PointModel* points) {
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
    // The device's own operations first: they may refine a raw op of the same name.
    const engine::Operation* own = operations.find(op);
    const auto raw = std::find_if(raw_ops.begin(), raw_ops.end(), [&](const auto& e) { return e.first == op; });
    if (own == nullptr && points != nullptr &&
        ((op == "write" && takes_point_write(*points)) || (op == "read" && takes_point_read(*points)))) {
        return point_command(command, id, op, *points);
    }
    if (own == nullptr && raw == raw_ops.end()) {
        std::string known;
        for (const std::string_view name : command_ops(operations, points)) {
            known += known.empty() ? "" : ", ";
            known += name;
        }
        return CommandError{CommandErrorKind::unknown_op,
                            "op '" + op + "' is not a " + std::string(operations.name) + " command (ops: " + known + ")",
                            id, op};
    }
    try {
        Fields fields(command);
        std::vector<Request> requests = own != nullptr ? device_op(fields, *own, registers) : raw->second(fields);
        fields.finish();
        return ParsedCommand{id, op, std::move(requests), {}};
    } catch (const Refusal& refusal) {
        return CommandError{refusal.kind, refusal.message, id, op};
    }
}

}  // namespace fieldbridge::northbound::mqtt
