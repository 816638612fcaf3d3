#include "config/validate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>


namespace fieldbridge::config {

void validate(const RawConfig& raw, const std::filesystem::path& base_dir, DiagnosticSink& sink) {
    if (!raw.ok()) {
        return;  // the root is not a map: already reported
    }
    validate_network(raw, sink);
    validate_lines(raw, sink);
    validate_mqtt(raw.mqtt, base_dir, sink);
    validate_sparkplug(raw, base_dir, sink);
    validate_uniqueness(raw, sink);
}

LineConfig framing_of(const RawLine& raw) {
    LineConfig framing;
    const auto& standard = LineConfig::standard_bauds;
    const bool standard_baud = raw.baud.has_value() && std::any_of(standard.begin(), standard.end(), [&](auto rate) {
                                   return std::int64_t{rate} == *raw.baud;
                               });
    if (standard_baud) {
        framing.baud = static_cast<std::uint32_t>(*raw.baud);
    }
    framing.parity = raw.parity.value_or(framing.parity);
    if (raw.data_bits.has_value() && (*raw.data_bits == 7 || *raw.data_bits == 8)) {
        framing.data_bits = static_cast<unsigned>(*raw.data_bits);
    }
    if (raw.stop_bits.has_value() && (*raw.stop_bits == 1 || *raw.stop_bits == 2)) {
        framing.stop_bits = static_cast<unsigned>(*raw.stop_bits);
    }
    return framing;
}

std::chrono::milliseconds character_times(const LineConfig& framing, double characters) {
    const double ns = characters * static_cast<double>(framing.character_time().count());
    return std::chrono::milliseconds{static_cast<std::int64_t>(std::ceil(ns / 1e6))};
}

std::chrono::milliseconds default_byte_timeout(const LineConfig& framing) {
    // Modbus over serial line V1.02 section 2.5.1.1: 3.5 character times end a frame.
    return std::max(LineConfig::default_byte_timeout, character_times(framing, 3.5));
}

bool default_precise_timing(const LineConfig& line) {
    // Measured (docs/configuration.md): a spun silence without a timer costs no more
    // CPU than the timer's wake-ups; a timer plus a spin costs up to the lead.
    return line.turnaround == std::chrono::milliseconds{0} && line.request_gap == std::chrono::milliseconds{0} &&
           line.character_time() * 7 / 2 < LineConfig::precise_timing_lead;
}

std::string framing_name(const LineConfig& framing) {
    const char parity = framing.parity == Parity::none ? 'N' : (framing.parity == Parity::even ? 'E' : 'O');
    return std::to_string(framing.data_bits) + parity + std::to_string(framing.stop_bits);
}

std::filesystem::path resolve_path(const std::filesystem::path& base_dir, const std::string& path) {
    const std::filesystem::path p(path);
    return (p.is_absolute() ? p : base_dir / p).lexically_normal();
}

bool is_valid_name(std::string_view name) noexcept {
    if (name.empty() || name.size() > max_name_length) {
        return false;
    }
    return std::all_of(name.begin(), name.end(), [](char c) {
        return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
    });
}

std::string hex16(std::int64_t value) {
    char buffer[16];
    std::snprintf(buffer, sizeof buffer, "0x%04llX", static_cast<unsigned long long>(value & 0xFFFF));
    return buffer;
}

std::string format_number(double value) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.10g", value);
    return buffer;
}

void check_backoff(DiagnosticSink& sink, const RawBackoff& backoff, const Backoff& defaults) {
    const bool initial_ok = backoff.initial.absent() || check_range(sink, backoff.initial, Backoff::range);
    const bool max_ok = backoff.max.absent() || check_range(sink, backoff.max, Backoff::range);
    if (!initial_ok || !max_ok || (backoff.initial.absent() && backoff.max.absent())) {
        return;
    }
    const auto initial = backoff.initial.value_or(defaults.initial);
    const auto max = backoff.max.value_or(defaults.max);
    if (max < initial) {
        const auto& culprit = backoff.max.has_value() ? backoff.max : backoff.initial;
        sink.error(culprit, "max (" + format_duration(max) + (backoff.max.has_value() ? "" : ", the default") +
                                ") is shorter than initial (" + format_duration(initial) +
                                (backoff.initial.has_value() ? "" : ", the default") + "); expected initial <= max");
    }
}

}  // namespace fieldbridge::config
