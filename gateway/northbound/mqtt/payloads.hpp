#pragma once
/// @file payloads.hpp
/// The JSON payloads of the MQTT topics (docs/mqtt.md), built with nlohmann-json from
/// plain values. Pure: the caller passes the wall-clock time.
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "engine/profiles/device_profile.hpp"
#include "protocol/modbus_pdu.hpp"
#include "northbound/mqtt/device_source.hpp"

namespace fieldbridge::northbound::mqtt {

using WallClock = std::chrono::system_clock;
using WallTime = WallClock::time_point;

/// Both clocks read at one moment: converts monotonic times to wall-clock times.
struct ClockPair {
    engine::TimePoint steady;
    WallTime wall;
    [[nodiscard]] WallTime to_wall(engine::TimePoint t) const noexcept {
        return wall - std::chrono::duration_cast<WallClock::duration>(steady - t);
    }
    [[nodiscard]] static ClockPair now() noexcept { return {engine::Clock::now(), WallClock::now()}; }
};

/// "2024-05-01T12:00:00.123Z" (ISO 8601, UTC, milliseconds).
[[nodiscard]] std::string iso8601_utc(WallTime time);
/// Milliseconds since the Unix epoch.
[[nodiscard]] std::int64_t epoch_ms(WallTime time) noexcept;

/// A decoded value as JSON (bool, integer, number or string).
[[nodiscard]] nlohmann::json to_json(const engine::FieldValue& value);

/// `<prefix>/<device>/state`: device, type, online, quality, time (of the newest
/// value; of @p clock when nothing was read), time_ms, fields, units, raw.
[[nodiscard]] nlohmann::json state_payload(std::string_view device, std::string_view type,
                                           const SourceState& state, const ClockPair& clock);

/// One active alarm and when it was raised.
struct ActiveAlarm {
    engine::Alarm alarm;
    engine::TimePoint since{};
    bool operator==(const ActiveAlarm&) const = default;
};

enum class AlarmTransition : std::uint8_t { raised, cleared };

struct AlarmEvent {
    AlarmTransition transition = AlarmTransition::raised;
    engine::Alarm alarm;
    engine::TimePoint time{};
    bool operator==(const AlarmEvent&) const = default;
};

/// `<prefix>/<device>/alarm`, not retained: {"event": "raised"|"cleared", code, ...}.
[[nodiscard]] nlohmann::json alarm_event_payload(std::string_view device, const AlarmEvent& event,
                                                 const ClockPair& clock);
/// `<prefix>/<device>/alarm`, retained: {"event": "active", "alarms": [...]}.
[[nodiscard]] nlohmann::json alarm_set_payload(std::string_view device, const std::vector<ActiveAlarm>& active,
                                               const ClockPair& clock);

/// How a command ended (`<prefix>/<device>/cmd/result`).
struct CommandOutcome {
    bool ok = true;
    std::string error;    ///< kind: "unknown_op", "rejected", "device_exception", "no_answer", ...
    std::string message;  ///< what failed and what to do
    std::optional<protocol::ExceptionCode> exception;  ///< the Modbus exception behind it, if any
    nlohmann::json values;  ///< `read` of points: {name: value, <name>_code: code}; null otherwise
};

/// The decoded values of the points @p names in @p state, as the state's `fields`
/// show them (an enum point with its `<name>_code`); a point without a value: null.
[[nodiscard]] nlohmann::json point_values(const SourceState& state, const std::vector<std::string>& names);

/// {"id", "device", "op", "ok", "values"?, "error"?, "message"?, "exception"?, "time", "time_ms"}.
[[nodiscard]] nlohmann::json command_result_payload(std::string_view device, const nlohmann::json& id,
                                                    std::string_view op, const CommandOutcome& outcome,
                                                    const ClockPair& clock);

/// "illegal data value (0x03)" etc.
[[nodiscard]] std::string exception_text(protocol::ExceptionCode code);

}  // namespace fieldbridge::northbound::mqtt
