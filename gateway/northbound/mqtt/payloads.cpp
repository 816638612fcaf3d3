#include "northbound/mqtt/payloads.hpp"

#include <array>
#include <ctime>
#include <cstdio>
#include <type_traits>
#include <variant>

namespace fieldbridge::northbound::mqtt {

namespace {

using nlohmann::json;

std::string hex4(std::uint16_t value) {
    std::array<char, 8> text{};
    std::snprintf(text.data(), text.size(), "0x%04X", static_cast<unsigned>(value));
    return text.data();
}

void put_time(json& out, const char* key, WallTime time) {
    out[key] = iso8601_utc(time);
    out[std::string(key) + "_ms"] = epoch_ms(time);
}

json alarm_fields(const engine::Alarm& alarm) {
    return json{{"code", alarm.code},
                {"text", alarm.text},
                {"severity", std::string(engine::to_string(alarm.severity))},
                {"source", alarm.source}};
}

}  // namespace

std::string iso8601_utc(WallTime time) {
    const auto ms = epoch_ms(time);
    // Floor division: times before 1970 keep a positive millisecond part.
    std::int64_t seconds = ms / 1000;
    std::int64_t millis = ms % 1000;
    if (millis < 0) {
        millis += 1000;
        seconds -= 1;
    }
    const auto t = static_cast<std::time_t>(seconds);
    std::tm utc{};
    gmtime_r(&t, &utc);
    // Room for every int the fields could hold (7 of 11 characters and the separators),
    // not only for real dates: GCC 14 cannot bound the calendar fields and warns
    // (-Wformat-truncation) for a buffer that fits "YYYY-MM-DDThh:mm:ss.mmmZ" alone.
    std::array<char, 96> text{};
    std::snprintf(text.data(), text.size(), "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", utc.tm_year + 1900, utc.tm_mon + 1,
                  utc.tm_mday, utc.tm_hour, utc.tm_min, utc.tm_sec, static_cast<int>(millis));
    return text.data();
}

std::int64_t epoch_ms(WallTime time) noexcept {
    return std::chrono::duration_cast<std::chrono::milliseconds>(time.time_since_epoch()).count();
}

json to_json(const engine::FieldValue& value) {
    return std::visit([](const auto& v) { return json(v); }, value);
}

json state_payload(std::string_view device, std::string_view type, const SourceState& state,
                   const ClockPair& clock) {
    json out;
    out["device"] = device;
    out["type"] = type;
    out["online"] = state.online;
    out["quality"] = std::string(engine::to_string(state.quality));
    put_time(out, "time", state.updated ? clock.to_wall(*state.updated) : clock.wall);
    json fields = json::object();
    json units = json::object();
    for (const engine::Field& field : state.decoded.fields) {
        fields[field.name] = to_json(field.value);
        if (!field.unit.empty()) {
            units[field.name] = field.unit;
        }
    }
    out["fields"] = std::move(fields);
    out["units"] = std::move(units);
    json raw = json::object();
    for (const RawRegister& r : state.raw) {
        raw[std::string(engine::to_string(r.table))][hex4(r.address)] = r.value;
    }
    out["raw"] = std::move(raw);
    return out;
}

json alarm_event_payload(std::string_view device, const AlarmEvent& event, const ClockPair& clock) {
    json out = alarm_fields(event.alarm);
    out["device"] = device;
    out["event"] = event.transition == AlarmTransition::raised ? "raised" : "cleared";
    put_time(out, "time", clock.to_wall(event.time));
    return out;
}

json alarm_set_payload(std::string_view device, const std::vector<ActiveAlarm>& active, const ClockPair& clock) {
    json alarms = json::array();
    for (const ActiveAlarm& a : active) {
        json item = alarm_fields(a.alarm);
        put_time(item, "since", clock.to_wall(a.since));
        alarms.push_back(std::move(item));
    }
    json out;
    out["device"] = device;
    out["event"] = "active";
    out["alarms"] = std::move(alarms);
    put_time(out, "time", clock.wall);
    return out;
}

json command_result_payload(std::string_view device, const json& id, std::string_view op,
                            const CommandOutcome& outcome, const ClockPair& clock) {
    json out;
    out["id"] = id;
    out["device"] = device;
    out["op"] = op;
    out["ok"] = outcome.ok;
    if (!outcome.values.is_null()) out["values"] = outcome.values;
    if (!outcome.ok) {
        out["error"] = outcome.error;
        out["message"] = outcome.message;
        if (outcome.exception) {
            out["exception"] = static_cast<int>(*outcome.exception);
        }
    }
    put_time(out, "time", clock.wall);
    return out;
}

json point_values(const SourceState& state, const std::vector<std::string>& names) {
    json out = json::object();
    for (const std::string& name : names) {
        const engine::Field* field = state.decoded.find(name);
        out[name] = field != nullptr ? to_json(field->value) : json();
        if (const engine::Field* code = state.decoded.find(name + "_code")) out[name + "_code"] = to_json(code->value);
    }
    return out;
}

std::string exception_text(protocol::ExceptionCode code) {
    const char* name = "exception";
    switch (code) {
        case protocol::ExceptionCode::illegal_function: name = "illegal function"; break;
        case protocol::ExceptionCode::illegal_data_address: name = "illegal data address"; break;
        case protocol::ExceptionCode::illegal_data_value: name = "illegal data value"; break;
        case protocol::ExceptionCode::server_device_failure: name = "server device failure"; break;
        case protocol::ExceptionCode::acknowledge: name = "acknowledge"; break;
        case protocol::ExceptionCode::server_device_busy: name = "server device busy"; break;
        case protocol::ExceptionCode::memory_parity_error: name = "memory parity error"; break;
        case protocol::ExceptionCode::gateway_path_unavailable: name = "gateway path unavailable"; break;
        case protocol::ExceptionCode::gateway_target_failed: name = "gateway target failed to respond"; break;
    }
    std::array<char, 8> hex{};
    std::snprintf(hex.data(), hex.size(), "0x%02X", static_cast<unsigned>(code));
    return std::string(name) + " (" + hex.data() + ")";
}

}  // namespace fieldbridge::northbound::mqtt
