#pragma once
/// @file transaction.hpp
/// One request on a half-duplex line and its outcome. The vocabulary shared by the
/// scheduler (which transaction goes next), the line master (timing and framing of
/// the one in flight), the line core and its shells (I/O) and the device agents (who
/// asked).

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <variant>

#include "protocol/modbus_pdu.hpp"
#include "protocol/wtec_ascii_commands.hpp"

namespace fieldbridge::engine {

using Clock = std::chrono::steady_clock;
using TimePoint = Clock::time_point;
using Duration = Clock::duration;
using std::chrono::milliseconds;

/// Index of a device on its line (0-based, config order). Broadcasts use
/// `broadcast_device`.
using DeviceIndex = std::uint16_t;
inline constexpr DeviceIndex broadcast_device = 0xFFFF;

/// Spec §3 rule 2: command > on-demand read > poll.
enum class Priority : std::uint8_t { command = 0, on_demand = 1, poll = 2 };

/// What goes on the wire.
struct ModbusPayload {
    protocol::Request request;
};
struct AsciiPayload {
    protocol::wtec::Command command;
};
using Payload = std::variant<ModbusPayload, AsciiPayload>;

enum class OutcomeStatus : std::uint8_t {
    ok,              ///< a valid reply arrived (a Modbus exception reply is ok too: see reply)
    timeout,         ///< no valid reply in time (after the retries allowed)
    expired,         ///< its deadline passed before it could start: never sent
    queue_full,      ///< the device's queue was full: never sent
    line_down,       ///< the port is not open: never sent
    device_offline,  ///< the device is offline and already holds its one queued request
    cancelled,       ///< shut down or reconfigured before it was sent
    broadcast_sent,  ///< broadcast written and the silence observed; no reply expected
    invalid_request, ///< cannot be carried (unknown device, unencodable request): never sent
    bad_reply,       ///< the device answered, with a frame (good CRC, its address) that does not fit the request
};

[[nodiscard]] const char* to_string(OutcomeStatus status) noexcept;

using Reply = std::variant<std::monostate, protocol::Response, protocol::wtec::Reply>;

struct Outcome {
    OutcomeStatus status = OutcomeStatus::timeout;
    Reply reply;                 ///< set when status == ok
    TimePoint finished{};        ///< when the outcome was decided
    unsigned attempts = 0;       ///< times it went on the wire
};

/// A request for the line. Moved into the scheduler, out to the master, and its
/// `on_done` is called exactly once with the outcome (on the line's loop thread).
struct Transaction {
    DeviceIndex device = 0;
    std::uint8_t address = 0;         ///< bus address (0 / 0xFF for broadcasts)
    Payload payload;
    Priority priority = Priority::poll;
    bool urgent = false;              ///< stop / e-stop: ahead of every other queued command (rule 4)
    bool retry_allowed = false;       ///< idempotent reads only (rule 6)
    std::optional<TimePoint> deadline;  ///< must START on the wire before this (rule 9)
    std::optional<Duration> poll_period;  ///< polls: for ageing (rule 3)
    Duration delay_before{};          ///< per-device delay before a command (rule 11)
    TimePoint enqueued{};
    std::uint64_t id = 0;             ///< set by the scheduler, for logs
    unsigned attempts = 0;            ///< times it went on the wire so far (set by the line master)
    std::function<void(const Outcome&)> on_done;
};

[[nodiscard]] inline bool is_broadcast(const Transaction& t) noexcept {
    return t.device == broadcast_device;
}

}  // namespace fieldbridge::engine
