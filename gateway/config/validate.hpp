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
#include <string>
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

/// Checks a back-off map: both durations in Backoff::range and initial <= max
/// (@p defaults stand in for absent values).
void check_backoff(DiagnosticSink& sink, const RawBackoff& backoff, const Backoff& defaults);

}  // namespace fieldbridge::config
