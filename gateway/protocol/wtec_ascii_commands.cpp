#include "protocol/wtec_ascii_commands.hpp"

#include <array>
#include <stdexcept>
#include <string_view>
#include <type_traits>

#include "core/error.hpp"

namespace fieldbridge::protocol::wtec {

namespace {

// Data widths in characters (seed 003, "指令集"; where the prose and a CRC-verified
// example disagree, the example wins, see tests/vectors/vectors.yaml).
constexpr std::size_t homing_width = 2 + 8 + 8 + 8 + 2 + 1 + 8 + 8;    // B / b: 45
constexpr std::size_t gripper_width = 8 + 2 + 2 + 2 + 1;               // N / n: 15
constexpr std::size_t driver_width = 8 + 8 + 2 + 1 + 2 + 2 + 4 + 8 + 1;  // R / r: 36
constexpr std::size_t pid_width = 4 + 4 + 4;                           // P / p: 12
// W / w: the prose says "24 bytes left blank" and 28 or 30 characters; only 26 '0'
// after current and speed (30 characters) make the examples' CRCs verify.
constexpr std::size_t release_padding = 26;
constexpr std::size_t release_width = 2 + 2 + release_padding;
constexpr std::size_t running_width = 8 + 2 + 1 + 2;  // I: 13
constexpr std::size_t target_width = 8;              // D (the example's 9 is a misprint)
constexpr std::size_t byte_width = 2;                // C, i, d, g, $
// A: the prose says 12 characters, the CRC-verified example "Cstep [A]1.62" has 13.
constexpr std::size_t version_min = 12;
constexpr std::size_t version_max = 13;

static_assert(homing_width == 45 && gripper_width == 15 && driver_width == 36 &&
              release_width == 30 && running_width == 13);

// ---- command letters ---------------------------------------------------------------
constexpr char letter(const ReadVersion&) { return 'A'; }
constexpr char letter(const ReadStations&) { return '$'; }
constexpr char letter(const SetMotorEnable&) { return 'a'; }
constexpr char letter(const ReadHoming&) { return 'B'; }
constexpr char letter(const WriteHoming&) { return 'b'; }
constexpr char letter(const SetPeakCurrent&) { return 'C'; }
constexpr char letter(const SetTarget&) { return 'D'; }
constexpr char letter(const QueryGripState&) { return 'd'; }
constexpr char letter(const GripperAction&) { return 'E'; }
constexpr char letter(const Home&) { return 'G'; }
constexpr char letter(const QueryHoming&) { return 'g'; }
constexpr char letter(const ReadRunning&) { return 'I'; }
constexpr char letter(const SetAddress&) { return 'i'; }
constexpr char letter(const ReadPid&) { return 'P'; }
constexpr char letter(const WritePid&) { return 'p'; }
constexpr char letter(const ReadGripper&) { return 'N'; }
constexpr char letter(const WriteGripper&) { return 'n'; }
constexpr char letter(const ReadDriver&) { return 'R'; }
constexpr char letter(const WriteDriver&) { return 'r'; }
constexpr char letter(const SaveAll&) { return 'U'; }
constexpr char letter(const ReadRelease&) { return 'W'; }
constexpr char letter(const WriteRelease&) { return 'w'; }
constexpr char letter(const CalibrateEncoder&) { return 'Z'; }

constexpr std::array<std::string_view, std::variant_size_v<Reply>> reply_names = {
    "Ack",   "NotExecuted", "Version",       "Station",      "HomingParams", "StateCode",
    "RunningValues", "Pid", "GripperParams", "DriverParams", "ReleaseParams"};

[[noreturn]] void throw_bad_value(char command, const std::string& what) {
    throw core::InvalidArgument(std::string("WTEC ASCII encode '") + command + "': " + what);
}

[[noreturn]] void refuse_reply(char command, const Reply& reply) {
    throw core::InvalidArgument(std::string("WTEC ASCII encode_reply: a ") +
                                std::string(reply_names[reply.index()]) +
                                " reply does not answer command '" + command + "'");
}

/// The alternative of @p reply that answers @p command, or an exception.
template <typename R>
[[nodiscard]] const R& reply_as(char command, const Reply& reply) {
    const auto* value = std::get_if<R>(&reply);
    if (value == nullptr) refuse_reply(command, reply);
    return *value;
}

// ---- writing fields ------------------------------------------------------------------
/// One-hex-digit fields cannot hold more than 0xF; refuse rather than truncate.
void put_digit(std::string& out, std::uint8_t value, char command, const char* field) {
    if (value > 0xF) {
        throw_bad_value(command, std::string(field) + " is " + std::to_string(value) +
                                     " but the field is one hex digit (0-15)");
    }
    append_hex(out, value, 1);
}

std::string homing_data(const HomingParams& p, char command) {
    std::string out;
    append_hex(out, p.mode, 2);
    append_hex(out, p.speed, 8);
    append_hex(out, p.acceleration, 8);
    append_hex(out, p.offset, 8);
    append_hex(out, p.current, 2);
    put_digit(out, p.sensor_mode, command, "sensor_mode");
    append_hex(out, p.confirm_time, 8);
    append_hex(out, p.max_distance, 8);
    return out;
}

std::string gripper_data(const GripperParams& p, char command) {
    std::string out;
    append_hex(out, p.target, 8);
    append_hex(out, p.max_current, 2);
    append_hex(out, p.speed, 2);
    append_hex(out, p.confirm_time, 2);
    put_digit(out, p.home_at_power_up, command, "home_at_power_up");
    return out;
}

std::string driver_data(const DriverParams& p, char command) {
    std::string out;
    append_hex(out, p.max_speed, 8);
    append_hex(out, p.max_acceleration, 8);
    append_hex(out, p.max_current, 2);
    put_digit(out, p.damping, command, "damping");
    append_hex(out, p.program, 2);
    append_hex(out, p.mode, 2);
    append_hex(out, p.pulses_per_revolution, 4);
    append_hex(out, p.following_error, 8);
    put_digit(out, p.multi_turn, command, "multi_turn");
    return out;
}

std::string pid_data(const Pid& p) {
    std::string out;
    append_hex(out, p.p, 4);
    append_hex(out, p.i, 4);
    append_hex(out, p.d, 4);
    return out;
}

std::string release_data(const ReleaseParams& p) {
    std::string out;
    append_hex(out, p.current, 2);
    append_hex(out, p.speed, 2);
    out.append(release_padding, '0');
    return out;
}

std::string running_data(const RunningValues& v) {
    std::string out;
    // Two's complement: the position 0xFFFFFFFD is -3 (seed 003, command 12).
    append_hex(out, static_cast<std::uint32_t>(v.position), 8);
    append_hex(out, v.current, 2);
    out.push_back(v.enabled ? '1' : '0');
    append_hex(out, v.state, 2);
    return out;
}

char action_digit(GripAction action, char command) {
    const auto value = static_cast<std::uint8_t>(action);
    if (value < 1 || value > 3) {
        throw_bad_value(command, "grip action " + std::to_string(value) +
                                     " is not 1 (grip), 2 (release) or 3 (toggle)");
    }
    return static_cast<char>('0' + value);
}

std::string byte_data(std::uint8_t value) {
    std::string out;
    append_hex(out, value, byte_width);
    return out;
}

std::string request_data(const Command& command) {
    const char cmd = letter_of(command);
    return std::visit(
        [cmd](const auto& c) -> std::string {
            using T = std::decay_t<decltype(c)>;
            if constexpr (std::is_same_v<T, SetMotorEnable>) {
                return c.enable ? "1" : "0";  // seed 003 command 3: 1 enable, 0 release
            } else if constexpr (std::is_same_v<T, WriteHoming>) {
                return homing_data(c.params, cmd);
            } else if constexpr (std::is_same_v<T, SetPeakCurrent>) {
                return byte_data(c.current);
            } else if constexpr (std::is_same_v<T, SetTarget>) {
                std::string out;
                append_hex(out, static_cast<std::uint32_t>(c.target), target_width);
                return out;
            } else if constexpr (std::is_same_v<T, GripperAction>) {
                return std::string(1, action_digit(c.action, cmd));
            } else if constexpr (std::is_same_v<T, SetAddress>) {
                if (c.new_address == broadcast_address || c.new_address > max_address) {
                    throw_bad_value(cmd, "new address " + std::to_string(c.new_address) +
                                             " is outside 1-253");
                }
                return byte_data(c.new_address);
            } else if constexpr (std::is_same_v<T, WritePid>) {
                return pid_data(c.pid);
            } else if constexpr (std::is_same_v<T, WriteGripper>) {
                return gripper_data(c.params, cmd);
            } else if constexpr (std::is_same_v<T, WriteDriver>) {
                return driver_data(c.params, cmd);
            } else if constexpr (std::is_same_v<T, WriteRelease>) {
                return release_data(c.params);
            } else {
                return {};  // read and action commands without data
            }
        },
        command);
}

// ---- reading fields ------------------------------------------------------------------
[[nodiscard]] bool all_hex(std::string_view data) noexcept {
    for (std::size_t i = 0; i < data.size(); ++i) {
        if (!parse_hex(data.substr(i, 1))) return false;
    }
    return true;
}

/// Reads consecutive fixed-width fields of data that has been checked to be hex.
class FieldReader {
public:
    explicit FieldReader(std::string_view data) noexcept : data_(data) {}

    template <typename T>
    [[nodiscard]] T next(std::size_t width) noexcept {
        const auto value = parse_hex(data_.substr(pos_, width));
        pos_ += width;
        return static_cast<T>(value.value_or(0));
    }

private:
    std::string_view data_;
    std::size_t pos_ = 0;
};

HomingParams read_homing(FieldReader& in) noexcept {
    HomingParams p;
    p.mode = in.next<std::uint8_t>(2);
    p.speed = in.next<std::uint32_t>(8);
    p.acceleration = in.next<std::uint32_t>(8);
    p.offset = in.next<std::uint32_t>(8);
    p.current = in.next<std::uint8_t>(2);
    p.sensor_mode = in.next<std::uint8_t>(1);
    p.confirm_time = in.next<std::uint32_t>(8);
    p.max_distance = in.next<std::uint32_t>(8);
    return p;
}

GripperParams read_gripper(FieldReader& in) noexcept {
    GripperParams p;
    p.target = in.next<std::uint32_t>(8);
    p.max_current = in.next<std::uint8_t>(2);
    p.speed = in.next<std::uint8_t>(2);
    p.confirm_time = in.next<std::uint8_t>(2);
    p.home_at_power_up = in.next<std::uint8_t>(1);
    return p;
}

DriverParams read_driver(FieldReader& in) noexcept {
    // seed 003 command 18: the prose's example values and the example frame disagree
    // on which value is which; decode by the documented field order and widths.
    DriverParams p;
    p.max_speed = in.next<std::uint32_t>(8);
    p.max_acceleration = in.next<std::uint32_t>(8);
    p.max_current = in.next<std::uint8_t>(2);
    p.damping = in.next<std::uint8_t>(1);
    p.program = in.next<std::uint8_t>(2);
    p.mode = in.next<std::uint8_t>(2);
    p.pulses_per_revolution = in.next<std::uint16_t>(4);
    p.following_error = in.next<std::uint32_t>(8);
    p.multi_turn = in.next<std::uint8_t>(1);
    return p;
}

Pid read_pid(FieldReader& in) noexcept {
    Pid p;
    p.p = in.next<std::uint16_t>(4);
    p.i = in.next<std::uint16_t>(4);
    p.d = in.next<std::uint16_t>(4);
    return p;
}

ReleaseParams read_release(FieldReader& in) noexcept {
    // The 26 reserved characters are hex-checked but not required to be '0': the
    // manual calls them blank ("留空") without saying a device must send zeros, so a
    // firmware that uses them is still understood. Encoders always send '0'.
    ReleaseParams p;
    p.current = in.next<std::uint8_t>(2);
    p.speed = in.next<std::uint8_t>(2);
    return p;
}

/// Checks @p data is exactly @p width hex digits, then builds the value with @p make
/// (which returns nullopt for a field value the protocol does not define).
template <typename V, typename Make>
[[nodiscard]] DecodeResult<V> fixed(std::string_view data, std::size_t width, Make make) {
    if (data.size() != width) return DecodeResult<V>::bad(DecodeError::bad_length, 0);
    if (!all_hex(data)) return DecodeResult<V>::bad(DecodeError::bad_hex, 0);
    FieldReader in(data);
    std::optional<V> value = make(in);
    if (!value) return DecodeResult<V>::bad(DecodeError::bad_value, 0);
    return DecodeResult<V>::ok(std::move(*value), 0);
}

template <typename V, typename T>
[[nodiscard]] DecodeResult<V> empty(std::string_view data) {
    return fixed<V>(data, 0, [](FieldReader&) -> std::optional<V> { return T{}; });
}

}  // namespace

char letter_of(const Command& command) noexcept {
    return std::visit([](const auto& c) { return letter(c); }, command);
}

AsciiFrame encode_command(std::uint8_t address, const Command& command) {
    // seed 003 command 2: '$' is sent to the broadcast address 00; every device answers.
    const std::uint8_t to =
        std::holds_alternative<ReadStations>(command) ? broadcast_address : address;
    return AsciiFrame{to, letter_of(command), request_data(command)};
}

DecodeResult<Command> decode_command(const AsciiFrame& frame) {
    using Result = DecodeResult<Command>;
    using Opt = std::optional<Command>;
    const std::string_view data = frame.data;
    switch (frame.command) {
        case 'A': return empty<Command, ReadVersion>(data);
        case '$': return empty<Command, ReadStations>(data);
        case 'a':
            return fixed<Command>(data, 1, [](FieldReader& in) -> Opt {
                const auto value = in.next<std::uint8_t>(1);
                if (value > 1) return std::nullopt;  // 1 enable, 0 release (command 3)
                return SetMotorEnable{value == 1};
            });
        case 'B': return empty<Command, ReadHoming>(data);
        case 'b':
            return fixed<Command>(data, homing_width,
                                  [](FieldReader& in) -> Opt { return WriteHoming{read_homing(in)}; });
        case 'C':
            return fixed<Command>(data, byte_width, [](FieldReader& in) -> Opt {
                return SetPeakCurrent{in.next<std::uint8_t>(byte_width)};
            });
        case 'D':
            return fixed<Command>(data, target_width, [](FieldReader& in) -> Opt {
                return SetTarget{static_cast<std::int32_t>(in.next<std::uint32_t>(target_width))};
            });
        case 'd': return empty<Command, QueryGripState>(data);
        case 'E':
            return fixed<Command>(data, 1, [](FieldReader& in) -> Opt {
                const auto value = in.next<std::uint8_t>(1);
                if (value < 1 || value > 3) return std::nullopt;  // E1 grip, E2 release, E3 toggle
                return GripperAction{static_cast<GripAction>(value)};
            });
        case 'G': return empty<Command, Home>(data);
        case 'g': return empty<Command, QueryHoming>(data);
        case 'I': return empty<Command, ReadRunning>(data);
        case 'i':
            return fixed<Command>(data, byte_width, [](FieldReader& in) -> Opt {
                const auto value = in.next<std::uint8_t>(byte_width);
                // Device addresses are 0x01-0xFD; 00 is broadcast (seed 003, overview).
                if (value == broadcast_address || value > max_address) return std::nullopt;
                return SetAddress{value};
            });
        case 'P': return empty<Command, ReadPid>(data);
        case 'p':
            return fixed<Command>(data, pid_width,
                                  [](FieldReader& in) -> Opt { return WritePid{read_pid(in)}; });
        case 'N': return empty<Command, ReadGripper>(data);
        case 'n':
            return fixed<Command>(data, gripper_width,
                                  [](FieldReader& in) -> Opt { return WriteGripper{read_gripper(in)}; });
        case 'R': return empty<Command, ReadDriver>(data);
        case 'r':
            return fixed<Command>(data, driver_width,
                                  [](FieldReader& in) -> Opt { return WriteDriver{read_driver(in)}; });
        case 'U': return empty<Command, SaveAll>(data);
        case 'W': return empty<Command, ReadRelease>(data);
        case 'w':
            return fixed<Command>(data, release_width,
                                  [](FieldReader& in) -> Opt { return WriteRelease{read_release(in)}; });
        case 'Z': return empty<Command, CalibrateEncoder>(data);
        default: return Result::bad(DecodeError::wrong_function, 0);
    }
}

AsciiFrame encode_reply(std::uint8_t address, const Command& command, const Reply& reply) {
    const char cmd = letter_of(command);
    AsciiFrame frame{address, cmd, {}};
    switch (cmd) {
        case 'A': {
            const auto& text = reply_as<Version>(cmd, reply).text;
            if (text.size() < version_min || text.size() > version_max) {
                throw_bad_value(cmd, "version text \"" + text + "\" is not 12 or 13 characters");
            }
            frame.data = text;  // encode_frame refuses non-printable characters
            break;
        }
        case '$': {
            const auto* station = &reply_as<Station>(cmd, reply);
            // The device answers from its own address and repeats it as data
            // (seed 003 command 2: ">01$01E2DF", ">02$02A79F").
            if (station->address != address) {
                throw_bad_value(cmd, "station " + std::to_string(station->address) +
                                         " differs from the replying address " +
                                         std::to_string(address));
            }
            frame.data = byte_data(station->address);
            break;
        }
        case 'B': frame.data = homing_data(reply_as<HomingParams>(cmd, reply), cmd); break;
        case 'd':
        case 'g': frame.data = byte_data(reply_as<StateCode>(cmd, reply).code); break;
        case 'I': frame.data = running_data(reply_as<RunningValues>(cmd, reply)); break;
        case 'P': frame.data = pid_data(reply_as<Pid>(cmd, reply)); break;
        case 'N': frame.data = gripper_data(reply_as<GripperParams>(cmd, reply), cmd); break;
        case 'R': frame.data = driver_data(reply_as<DriverParams>(cmd, reply), cmd); break;
        case 'W': frame.data = release_data(reply_as<ReleaseParams>(cmd, reply)); break;
        case 'D':
        case 'E':
            // seed 003 command 9: a drive that is not homed answers `E` with the
            // request itself ("返回原指令"), e.g. >01E14EA0; `D` is refused the same
            // way (docs/protocols.md).
            if (std::holds_alternative<NotExecuted>(reply)) {
                frame.data = request_data(command);
            } else if (!std::holds_alternative<Ack>(reply)) {
                refuse_reply(cmd, reply);
            }
            break;
        case 'i':
            // seed 003 command 13: the reply already comes from the new address (>0AiBDFD).
            if (!std::holds_alternative<Ack>(reply)) refuse_reply(cmd, reply);
            frame.address = std::get<SetAddress>(command).new_address;
            break;
        default:
            // a b C D G n p r U w Z: an empty acknowledgement; for G and U it is the
            // request frame itself (seed 003 commands 10 and 20).
            if (!std::holds_alternative<Ack>(reply)) refuse_reply(cmd, reply);
            break;
    }
    return frame;
}

DecodeResult<Reply> decode_reply(std::uint8_t address, const Command& command,
                                 const AsciiFrame& frame) {
    using Result = DecodeResult<Reply>;
    using Opt = std::optional<Reply>;
    const char cmd = letter_of(command);
    if (std::holds_alternative<ReadStations>(command)) {
        // '$' goes to everyone; a reply comes from any device address but never 00.
        if (frame.address == broadcast_address || frame.address > max_address) {
            return Result::bad(DecodeError::wrong_address, 0);
        }
    } else {
        const auto* set = std::get_if<SetAddress>(&command);
        const std::uint8_t expected = set != nullptr ? set->new_address : address;
        if (frame.address != expected) return Result::bad(DecodeError::wrong_address, 0);
    }
    if (frame.command != cmd) return Result::bad(DecodeError::unexpected_reply, 0);

    const std::string_view data = frame.data;
    switch (cmd) {
        case 'A': {
            if (data.size() < version_min || data.size() > version_max) {
                return Result::bad(DecodeError::bad_length, 0);
            }
            for (const char c : data) {
                if (!is_data_char(c)) return Result::bad(DecodeError::bad_value, 0);
            }
            return Result::ok(Version{std::string(data)}, 0);
        }
        case '$': {
            const std::uint8_t from = frame.address;
            return fixed<Reply>(data, byte_width, [from](FieldReader& in) -> Opt {
                const auto station = in.next<std::uint8_t>(byte_width);
                if (station != from) return std::nullopt;  // ">01$01": data repeats the address
                return Station{station};
            });
        }
        case 'B':
            return fixed<Reply>(data, homing_width, [](FieldReader& in) -> Opt { return read_homing(in); });
        case 'd':
        case 'g':
            // Unknown state codes are passed on: the profile decides what they mean.
            return fixed<Reply>(data, byte_width, [](FieldReader& in) -> Opt {
                return StateCode{in.next<std::uint8_t>(byte_width)};
            });
        case 'I':
            return fixed<Reply>(data, running_width, [](FieldReader& in) -> Opt {
                RunningValues v;
                v.position = static_cast<std::int32_t>(in.next<std::uint32_t>(8));
                v.current = in.next<std::uint8_t>(2);
                const auto enable = in.next<std::uint8_t>(1);
                if (enable > 1) return std::nullopt;
                v.enabled = enable == 1;
                v.state = in.next<std::uint8_t>(2);
                return v;
            });
        case 'P':
            return fixed<Reply>(data, pid_width, [](FieldReader& in) -> Opt { return read_pid(in); });
        case 'N':
            return fixed<Reply>(data, gripper_width, [](FieldReader& in) -> Opt { return read_gripper(in); });
        case 'R':
            return fixed<Reply>(data, driver_width, [](FieldReader& in) -> Opt { return read_driver(in); });
        case 'W':
            return fixed<Reply>(data, release_width, [](FieldReader& in) -> Opt { return read_release(in); });
        case 'D':
        case 'E': {
            // An acknowledgement carries no data; only an exact echo of the request's
            // data means "not executed" (seed 003 command 9, "返回原指令").
            if (data.empty()) return Result::ok(Ack{}, 0);
            const std::string sent = request_data(command);
            if (data.size() != sent.size()) return Result::bad(DecodeError::bad_length, 0);
            if (!all_hex(data)) return Result::bad(DecodeError::bad_hex, 0);
            if (data != sent) return Result::bad(DecodeError::unexpected_reply, 0);
            return Result::ok(NotExecuted{}, 0);
        }
        default:
            return empty<Reply, Ack>(data);
    }
}

}  // namespace fieldbridge::protocol::wtec
