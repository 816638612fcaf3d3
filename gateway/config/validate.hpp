#pragma once
/// @file validate.hpp
/// Step 2 of loading: checks a RawConfig against the limits named in config.hpp,
/// the required keys, and the relations between values (unique unit IDs, names,
/// ports and addresses; type-specific keys; timing that makes sense at the baud;
/// files that must exist). Reports everything it finds; never stops early.
/// Internal to the config layer.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>
#include <string_view>

#include "config/config.hpp"
#include "config/diagnostic_sink.hpp"
#include "config/raw_config.hpp"
#include "config/scalars.hpp"

namespace fieldbridge::config {

/// @p base_dir resolves relative file paths (TLS files, password file).
void validate(const RawConfig& raw, const std::filesystem::path& base_dir, DiagnosticSink& sink);

// ---- the parts, one file each ----------------------------------------------------
void validate_lines(const RawConfig& raw, DiagnosticSink& sink);      // validate_lines.cpp
void validate_devices(const RawLine& line, DiagnosticSink& sink);     // validate_devices.cpp
void validate_network(const RawConfig& raw, DiagnosticSink& sink);    // validate_network.cpp
void validate_mqtt(const RawMqtt& mqtt, const std::filesystem::path& base_dir, DiagnosticSink& sink);
void validate_uniqueness(const RawConfig& raw, DiagnosticSink& sink);  // validate_uniqueness.cpp
void validate_sparkplug(const RawConfig& raw, const std::filesystem::path& base_dir,
                        DiagnosticSink& sink);                         // validate_sparkplug.cpp

// ---- MQTT connection settings, shared by mqtt and sparkplug (validate_mqtt.cpp) ----

struct MqttCredentialFields {
    const Field<std::string>& username;
    const Field<std::string>& password;
    const Field<std::string>& password_file;
    std::string_view version_hint;  ///< appended to "expected username to be set too"
};
/// password and password_file not both; the file readable; a password needs a
/// username in MQTT 3.1.1.
void check_mqtt_credentials(const MqttCredentialFields& fields, MqttVersion version,
                            const std::filesystem::path& base_dir, DiagnosticSink& sink);
/// The TLS files exist; key_file needs cert_file; TLS settings need a TLS URI
/// (@p tls_uri), else @p uri_hint is reported.
void check_mqtt_tls(const RawTls& tls, bool tls_uri, std::string_view uri_hint, const std::filesystem::path& base_dir,
                    DiagnosticSink& sink);
/// 1..128 printable characters without spaces.
void check_mqtt_client_id(const Field<std::string>& client_id, DiagnosticSink& sink);

// ---- shared helpers ----------------------------------------------------------------

/// Serial framing of a raw line (baud, parity, data and stop bits), with the
/// defaults for values that are absent or invalid.
[[nodiscard]] LineConfig framing_of(const RawLine& raw);
/// @p characters character times at @p framing, rounded up to whole milliseconds.
[[nodiscard]] std::chrono::milliseconds character_times(const LineConfig& framing, double characters);
/// The byte_timeout used when the file does not set one: 5ms, or 3.5 character
/// times when that is longer.
[[nodiscard]] std::chrono::milliseconds default_byte_timeout(const LineConfig& framing);
/// The precise_timing used when the file does not set one: true when the silence
/// before a request (3.5 characters; the turnaround when one is set) is shorter than
/// LineConfig::precise_timing_lead, so that it is spun whole, without a timer.
[[nodiscard]] bool default_precise_timing(const LineConfig& line);
/// "8N1", "7E2"...
[[nodiscard]] std::string framing_name(const LineConfig& framing);

/// A relative path is taken relative to @p base_dir.
[[nodiscard]] std::filesystem::path resolve_path(const std::filesystem::path& base_dir, const std::string& path);

/// [A-Za-z0-9_-], 1..64 characters.
[[nodiscard]] bool is_valid_name(std::string_view name) noexcept;

/// "0x0600" for register addresses.
[[nodiscard]] std::string hex16(std::int64_t value);

/// Reports a required key that is absent. Returns true when the field has a value.
template <class T>
bool require(DiagnosticSink& sink, const Field<T>& field, std::string_view expected) {
    if (field.absent()) {
        sink.error(field, "required key is missing; expected " + std::string(expected));
    }
    return field.has_value();
}

/// Reports an integer outside @p range. Returns true when it has a value in range.
inline bool check_range(DiagnosticSink& sink, const Field<std::int64_t>& field, Range<std::int64_t> range) {
    if (!field.has_value()) {
        return false;
    }
    if (!range.contains(*field)) {
        sink.error(field, std::to_string(*field) + " is out of range; expected " + std::to_string(range.min) + ".." +
                              std::to_string(range.max));
        return false;
    }
    return true;
}

/// Reports a duration outside @p range. Returns true when it has a value in range.
inline bool check_range(DiagnosticSink& sink, const Field<std::chrono::milliseconds>& field,
                        Range<std::chrono::milliseconds> range) {
    if (!field.has_value()) {
        return false;
    }
    if (!range.contains(*field)) {
        sink.error(field, format_duration(*field) + " is out of range; expected " + format_duration(range.min) +
                              ".." + format_duration(range.max));
        return false;
    }
    return true;
}

/// Reports a name that breaks is_valid_name().
inline bool check_name(DiagnosticSink& sink, const Field<std::string>& field) {
    if (!field.has_value()) {
        return false;
    }
    if (!is_valid_name(*field)) {
        sink.error(field, "'" + *field + "' is not a valid name; expected 1.." + std::to_string(max_name_length) +
                              " characters from A-Z a-z 0-9 _ - (it becomes an MQTT topic level)");
        return false;
    }
    return true;
}

// ---- points (validate_points.cpp) -------------------------------------------------

/// A point as far as the other points and the alarms need it.
struct PointSpan {
    std::string name;
    std::string path;  ///< key path in `file`
    std::string file;
    int line = 0;
    const RawPoint* raw = nullptr;
    core::PointType type = core::PointType::uint16;
    bool shape_ok = false;  ///< table, address and width valid: the fields below are set
    RegisterTable table = RegisterTable::holding;
    bool bit = false;  ///< a `bit:` point
    bool text = false;  ///< its format is a template: a text, not a number
    std::int64_t first = 0;
    std::int64_t last = 0;
};

/// snake_case: [a-z][a-z0-9_]*, 1..64 characters (points and alarms; a JSON field).
[[nodiscard]] bool is_point_name(std::string_view name) noexcept;
bool check_point_name(DiagnosticSink& sink, const Field<std::string>& field);
/// `type:`, or its default: bool for a bit table or with `bit:`, else uint16.
[[nodiscard]] core::PointType effective_type(const RawPoint& point) noexcept;
/// Checks each point and its relations to @p earlier (a definition's points when
/// these are a device's inline ones) and to the points before it; returns @p
/// earlier with these added.
[[nodiscard]] std::vector<PointSpan> check_points(const RawSeq<RawPoint>& points, std::vector<PointSpan> earlier,
                                                  DiagnosticSink& sink);
/// Checks alarms against @p points; @p earlier are alarm names already used in the
/// device. Returns @p earlier with these names added.
std::vector<std::string> check_alarms(const RawSeq<RawAlarm>& alarms, const std::vector<PointSpan>& points,
                                      std::vector<std::string> earlier, DiagnosticSink& sink);
/// `equals:` / `not_equals:` of an alarm: a number, or an enum label of @p point.
[[nodiscard]] std::optional<double> alarm_value(const Field<std::string>& field, const RawPoint& point);

/// `blocks:`: limits, read-only tables, and no overlap with each other nor with
/// @p earlier (a definition's blocks; may be null) (validate_devices.cpp).
void check_blocks(const RawSeq<RawBlock>& blocks, const RawSeq<RawBlock>* earlier, DiagnosticSink& sink);

/// A definition's name (its file's stem): [a-z0-9][a-z0-9_-]*, 1..64 characters.
[[nodiscard]] bool is_definition_name(std::string_view name) noexcept;

/// A device definition on its own: its keys, points, alarms, blocks and identify
/// read; @p stem is its file name without `.yaml` (validate_definition.cpp).
void validate_definition(const RawDefinition& definition, std::string_view stem, DiagnosticSink& sink);

/// `registers:` and the keys that go with `behaviour:` (validate_registers.cpp): a
/// definition with a hook has rows of registers and no points, alarms, blocks,
/// identify, word_order, period or max_gap; one without has no registers.
void check_registers(const RawDefinition& definition, DiagnosticSink& sink);

/// A number as written in messages: 21.5, 1e+06.
[[nodiscard]] std::string format_number(double value);

/// Checks a back-off map: both durations in Backoff::range and initial <= max
/// (@p defaults stand in for absent values).
void check_backoff(DiagnosticSink& sink, const RawBackoff& backoff, const Backoff& defaults);

}  // namespace fieldbridge::config
