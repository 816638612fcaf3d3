#pragma once
/// @file wtec_ascii_commands.hpp
/// Typed encoders and decoders for every command of the WTEC-485 ASCII protocol
/// (seed 003, "指令集": A $ a B b C D d E G g I i P p N n R r U W w Z).
/// Field widths follow the manual's CRC-verified examples where the prose and the
/// example disagree (vectors.yaml marks each such case). Replies are parsed
/// strictly: exact data length per command, hex digits only (upper case, see
/// wtec_ascii_frame.hpp).
///
/// Encoders throw core::InvalidArgument for a value the wire cannot carry (a
/// one-digit field above 0xF, an `E` action outside 1-3, an `i` address outside
/// 1-253, a reply type that does not answer the command). Decoders return values;
/// `consumed` is 0 in their results because they take a frame scan_frame already
/// took off the line.

#include <cstdint>
#include <optional>
#include <string>
#include <variant>

#include "protocol/decode_result.hpp"
#include "protocol/wtec_ascii_frame.hpp"

namespace fieldbridge::protocol::wtec {

/// `B` reply / `b` request: 2+8+8+8+2+1+8+8 = 45 hex digits.
struct HomingParams {
    /// 0xFC "reverse collision homing": homes at the open end (init direction 1, the
    /// default); 0xFD forward: homes at the closed end (direction 2). docs/registers.md.
    std::uint8_t mode = 0xFC;
    std::uint32_t speed = 0;
    std::uint32_t acceleration = 0;
    std::uint32_t offset = 0;
    std::uint8_t current = 0;
    std::uint8_t sensor_mode = 0;  ///< one hex digit; 1 = normally closed
    std::uint32_t confirm_time = 0;
    std::uint32_t max_distance = 0;
    bool operator==(const HomingParams&) const = default;
};

/// `N` reply / `n` request: 8+2+2+2+1 = 15 hex digits.
struct GripperParams {
    std::uint32_t target = 0;      ///< target coordinate (encoder counts)
    std::uint8_t max_current = 0;  ///< the grip current (`C` sets it too)
    std::uint8_t speed = 0;        ///< 0x00-0xFF
    std::uint8_t confirm_time = 0;
    std::uint8_t home_at_power_up = 0;  ///< one hex digit
    bool operator==(const GripperParams&) const = default;
};

/// `R` reply / `r` request: 8+8+2+1+2+2+4+8+1 = 36 hex digits, decoded by position.
struct DriverParams {
    std::uint32_t max_speed = 0;
    std::uint32_t max_acceleration = 0;
    std::uint8_t max_current = 0;  ///< max running current: the current at 100 % Modbus force
    std::uint8_t damping = 0;  ///< one hex digit
    std::uint8_t program = 0;
    std::uint8_t mode = 0;
    std::uint16_t pulses_per_revolution = 0;
    std::uint32_t following_error = 0;
    std::uint8_t multi_turn = 0;  ///< one hex digit
    bool operator==(const DriverParams&) const = default;
};

/// `P` reply / `p` request: 4+4+4 hex digits.
struct Pid {
    std::uint16_t p = 0;
    std::uint16_t i = 0;
    std::uint16_t d = 0;
    bool operator==(const Pid&) const = default;
};

/// `W` reply / `w` request: 2+2 hex digits then 26 '0' (30 data characters).
/// The 26 reserved characters are encoded as '0'; on decode they must be hex
/// digits but may be any (the manual only calls them blank).
struct ReleaseParams {
    std::uint8_t current = 0;
    std::uint8_t speed = 0;
    bool operator==(const ReleaseParams&) const = default;
};

/// `I` reply: 8 (signed 32-bit position) + 2 current + 1 enable + 2 state.
struct RunningValues {
    std::int32_t position = 0;
    std::uint8_t current = 0;
    bool enabled = false;
    std::uint8_t state = 0;  ///< same codes as `d`
    bool operator==(const RunningValues&) const = default;
};

/// Grip states of `d` and `I` (seed 003, command 8).
namespace grip_state {
inline constexpr std::uint8_t moving = 0x00;
inline constexpr std::uint8_t reached = 0x01;
inline constexpr std::uint8_t gripped = 0x02;
inline constexpr std::uint8_t released_to_limit = 0x05;
inline constexpr std::uint8_t closed_without_object = 0x06;
inline constexpr std::uint8_t motor_released = 0x11;
}  // namespace grip_state

/// Homing states of `g` (seed 003, command 11).
namespace homing_state {
inline constexpr std::uint8_t not_homed = 0x00;
inline constexpr std::uint8_t homed = 0x01;
inline constexpr std::uint8_t failed = 0x02;
inline constexpr std::uint8_t beyond_limit = 0x03;
inline constexpr std::uint8_t homing = 0x09;
}  // namespace homing_state

/// `E` actions.
enum class GripAction : std::uint8_t { grip = 1, release = 2, toggle = 3 };

// ---- requests (host -> gripper) -------------------------------------------------
struct ReadVersion { bool operator==(const ReadVersion&) const = default; };             // A
struct ReadStations { bool operator==(const ReadStations&) const = default; };           // $ (address 00)
struct SetMotorEnable { bool enable = false; bool operator==(const SetMotorEnable&) const = default; };  // a
struct ReadHoming { bool operator==(const ReadHoming&) const = default; };               // B
struct WriteHoming { HomingParams params; bool operator==(const WriteHoming&) const = default; };      // b
/// `C` "set the running peak current": the grip current, the `N` max current.
struct SetPeakCurrent { std::uint8_t current = 0; bool operator==(const SetPeakCurrent&) const = default; };  // C
struct SetTarget { std::int32_t target = 0; bool operator==(const SetTarget&) const = default; };      // D (8 hex)
struct QueryGripState { bool operator==(const QueryGripState&) const = default; };       // d
struct GripperAction { GripAction action = GripAction::grip; bool operator==(const GripperAction&) const = default; };  // E
struct Home { bool operator==(const Home&) const = default; };                           // G
struct QueryHoming { bool operator==(const QueryHoming&) const = default; };             // g
struct ReadRunning { bool operator==(const ReadRunning&) const = default; };             // I
struct SetAddress { std::uint8_t new_address = 0; bool operator==(const SetAddress&) const = default; };  // i
struct ReadPid { bool operator==(const ReadPid&) const = default; };                     // P
struct WritePid { Pid pid; bool operator==(const WritePid&) const = default; };          // p
struct ReadGripper { bool operator==(const ReadGripper&) const = default; };             // N
struct WriteGripper { GripperParams params; bool operator==(const WriteGripper&) const = default; };  // n
struct ReadDriver { bool operator==(const ReadDriver&) const = default; };               // R
struct WriteDriver { DriverParams params; bool operator==(const WriteDriver&) const = default; };     // r
struct SaveAll { bool operator==(const SaveAll&) const = default; };                     // U
struct ReadRelease { bool operator==(const ReadRelease&) const = default; };             // W
struct WriteRelease { ReleaseParams params; bool operator==(const WriteRelease&) const = default; };  // w
struct CalibrateEncoder { bool operator==(const CalibrateEncoder&) const = default; };   // Z

using Command = std::variant<ReadVersion, ReadStations, SetMotorEnable, ReadHoming, WriteHoming,
                             SetPeakCurrent, SetTarget, QueryGripState, GripperAction, Home,
                             QueryHoming, ReadRunning, SetAddress, ReadPid, WritePid, ReadGripper,
                             WriteGripper, ReadDriver, WriteDriver, SaveAll, ReadRelease,
                             WriteRelease, CalibrateEncoder>;

[[nodiscard]] char letter_of(const Command& command) noexcept;

/// The request frame for @p command to @p address (ReadStations goes to address 0).
[[nodiscard]] AsciiFrame encode_command(std::uint8_t address, const Command& command);

/// Decodes a request frame (simulator side): letter known (else wrong_function),
/// data length (bad_length) and hex digits (bad_hex) exact, `a` 0/1, `E` 1-3 and
/// `i` 01-FD (else bad_value). The frame's address is left to the caller.
[[nodiscard]] DecodeResult<Command> decode_command(const AsciiFrame& frame);

// ---- replies (gripper -> host) --------------------------------------------------
struct Ack { bool operator==(const Ack&) const = default; };  ///< reply with no data (a b C D E G i n p r U w Z)
/// `E` or `D` answered by an echo of the request: the gripper did nothing (seed 003
/// command 9: `E` before homing; `D` likewise, e.g. with the motor released).
struct NotExecuted { bool operator==(const NotExecuted&) const = default; };
/// `A`: printable text of 12 (the manual's prose) or 13 characters (its CRC-verified
/// example "Cstep [A]1.62").
struct Version { std::string text; bool operator==(const Version&) const = default; };  // A
struct Station { std::uint8_t address = 0; bool operator==(const Station&) const = default; };  // $
struct StateCode { std::uint8_t code = 0; bool operator==(const StateCode&) const = default; };  // d, g

using Reply = std::variant<Ack, NotExecuted, Version, Station, HomingParams, StateCode, RunningValues,
                           Pid, GripperParams, DriverParams, ReleaseParams>;

/// The reply frame a device sends for @p command (simulator side). For `i` the reply
/// comes from the new address; for `$` from the device's own address; `G` and `U`
/// are answered with the request's own frame, as the manual shows.
[[nodiscard]] AsciiFrame encode_reply(std::uint8_t address, const Command& command, const Reply& reply);

/// Decodes @p frame as the reply to @p command sent to @p address: the letter must
/// match, the address must be the one asked (for `i`, the new one; for `$`, any
/// device address 01-FD, repeated as the data), the data length and digits exact.
/// Otherwise malformed: wrong_address (checked first), unexpected_reply (another
/// letter, or `E` / `D` data that is not the request's own), bad_length, bad_hex, bad_value (an
/// enable flag other than 0/1, a `$` station that differs from the frame address).
[[nodiscard]] DecodeResult<Reply> decode_reply(std::uint8_t address, const Command& command,
                                               const AsciiFrame& frame);

}  // namespace fieldbridge::protocol::wtec
