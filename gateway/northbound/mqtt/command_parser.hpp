#pragma once
/// @file command_parser.hpp
/// `<prefix>/<device>/cmd` payloads -> Modbus requests (docs/mqtt.md, "Commands").
/// A command is a JSON object with an `id` (string or number, echoed in the result),
/// an `op` of the device's operations, and the op's fields; nothing else. The parser
/// knows no device: it checks the fields against the operation's specs (JSON types,
/// the ranges the profile can state without the device, engine/profiles/operations.hpp)
/// and asks the operation for its requests, which may depend on the device's register
/// values (an op that needs one the gateway does not hold is refused, state_unknown).
/// The device's profile checks the rest (model-dependent strokes, protected
/// registers) before anything is sent. The raw register ops `set_register` and
/// `write_registers` are the parser's own: every device takes them. Pure.
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/point.hpp"
#include "northbound/mqtt/device_source.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::northbound::mqtt {

/// A command ready to execute: its requests go out in order, each after the previous
/// one was acknowledged.
struct ParsedCommand {
    nlohmann::json id;
    std::string op;
    std::vector<protocol::Request> requests;
    /// `read` of a device with points: the points the result carries (docs/mqtt.md).
    std::vector<std::string> read_points;
};

/// Why a command was refused before anything was sent.
enum class CommandErrorKind : std::uint8_t {
    bad_json,       ///< not JSON, or not an object
    missing_id,     ///< no `id`, or not a string / number
    unknown_op,     ///< no `op`, or not one of the device's operations
    missing_field,
    invalid_field,  ///< wrong JSON type, or a field the op does not take
    out_of_range,
    state_unknown,  ///< the op needs a device register the gateway has no usable value of
};
/// "bad_json", "missing_id", "unknown_op", "missing_field", "invalid_field", "out_of_range",
/// "state_unknown".
[[nodiscard]] std::string_view to_string(CommandErrorKind kind) noexcept;

struct CommandError {
    CommandErrorKind kind = CommandErrorKind::bad_json;
    std::string message;    ///< names the field and what is expected
    nlohmann::json id;      ///< null when the command had no usable id
    std::string op;         ///< empty when unknown
};

using ParseResult = std::variant<ParsedCommand, CommandError>;

/// @p operations: the device's (DeviceSource::operations()); @p registers: its
/// register image as the source shows it (SourceState::raw: every register that has
/// a value); ops that need none ignore it. @p points: the device's points (nullptr:
/// none), which add the ops `write` and `read` (point_commands.hpp).
[[nodiscard]] ParseResult parse_command(std::string_view payload, const engine::OperationSet& operations,
                                        std::span<const RawRegister> registers,
                                        const core::PointModel* points = nullptr);

/// The ops a device of @p operations takes: its own, then the point ops, then the raw
/// register ops (for error messages and docs).
[[nodiscard]] std::vector<std::string_view> command_ops(const engine::OperationSet& operations,
                                                        const core::PointModel* points = nullptr);

}  // namespace fieldbridge::northbound::mqtt
