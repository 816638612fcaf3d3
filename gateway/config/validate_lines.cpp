#include <algorithm>
#include <cstdio>

#include "config/validate.hpp"

namespace fieldbridge::config {

namespace {

[[nodiscard]] std::string baud_list() {
    std::string out;
    for (const auto rate : LineConfig::standard_bauds) {
        out += (out.empty() ? "" : ", ") + std::to_string(rate);
    }
    return out;
}

[[nodiscard]] std::string format_ms(std::chrono::nanoseconds ns) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.2f ms", static_cast<double>(ns.count()) / 1e6);
    return buffer;
}

void check_serial(const RawLine& line, DiagnosticSink& sink) {
    if (line.baud.has_value()) {
        const auto& rates = LineConfig::standard_bauds;
        if (std::none_of(rates.begin(), rates.end(), [&](auto r) { return std::int64_t{r} == *line.baud; })) {
            sink.error(line.baud, std::to_string(*line.baud) + " is not a standard rate; expected one of " + baud_list());
        }
    }
    if (line.data_bits.has_value() && *line.data_bits != 7 && *line.data_bits != 8) {
        sink.error(line.data_bits, std::to_string(*line.data_bits) + " is not supported; expected 7 or 8");
    }
    if (line.stop_bits.has_value() && *line.stop_bits != 1 && *line.stop_bits != 2) {
        sink.error(line.stop_bits, std::to_string(*line.stop_bits) + " is not supported; expected 1 or 2");
    }
    if (line.rs485.ok()) {
        check_range(sink, line.rs485.delay_before_send, Rs485Config::delay_range);
        check_range(sink, line.rs485.delay_after_send, Rs485Config::delay_range);
    }
}

/// Timeouts must leave room for the frame timing of Modbus over serial line V1.02
/// section 2.5.1.1 at the configured baud: a device starts answering only after
/// the 3.5-character silence that ends the request, and characters of one frame
/// may be up to 1.5 character times apart.
void check_timing(const RawLine& line, DiagnosticSink& sink) {
    const LineConfig framing = framing_of(line);
    const std::string at = " at " + std::to_string(framing.baud) + " bit/s " + framing_name(framing);
    if (check_range(sink, line.response_timeout, LineConfig::response_timeout_range)) {
        const auto silence = character_times(framing, 3.5);
        if (*line.response_timeout < silence) {
            sink.error(line.response_timeout,
                       format_duration(*line.response_timeout) + " is shorter than the 3.5-character silence" + at +
                           " (" + format_ms(framing.character_time() * 7 / 2) +
                           "), so no device could ever answer in time; expected at least " + format_duration(silence));
        }
    }
    const auto check_gap = [&](const Field<std::chrono::milliseconds>& field, Range<std::chrono::milliseconds> range) {
        if (!check_range(sink, field, range)) return;
        const auto gap = character_times(framing, 1.5);
        if (*field < gap) {
            sink.error(field, format_duration(*field) + " is shorter than the 1.5-character gap allowed inside a frame" +
                                  at + " (" + format_ms(framing.character_time() * 3 / 2) +
                                  "), so replies would be cut; expected at least " + format_duration(gap));
        }
    };
    check_gap(line.byte_timeout, LineConfig::byte_timeout_range);
    check_gap(line.tcp_frame_gap, LineConfig::tcp_frame_gap_range);
    check_range(sink, line.turnaround, LineConfig::turnaround_range);
    check_range(sink, line.broadcast_delay, LineConfig::broadcast_delay_range);
    check_range(sink, line.read_retries, LineConfig::read_retries_range);
    check_range(sink, line.offline_after, LineConfig::offline_after_range);
    check_backoff(sink, line.offline_backoff, LineConfig{}.offline_backoff);
}

/// A tcp:// port reaches the line through a serial device server: the RS-485 set-up
/// and the echo of a local adapter are the device server's business, and a stream
/// shows no inter-byte silence (tcp_frame_gap replaces byte_timeout). A serial port
/// has no connection to time or retry.
void check_transport(const RawLine& line, DiagnosticSink& sink) {
    const bool tcp = line.port.has_value() && is_tcp_port(*line.port);
    const std::string on_tcp = " does not apply to a tcp:// port: the serial device server drives the line";
    if (tcp) {
        if (!line.rs485.absent()) {
            sink.error(line.rs485, "rs485" + on_tcp + "; set its RS-485 mode in the device server and remove rs485");
        }
        if (line.local_echo.has_value()) {
            sink.error(line.local_echo, "local_echo" + on_tcp + "; remove it");
        }
        if (line.byte_timeout.has_value()) {
            sink.error(line.byte_timeout, "byte_timeout does not apply to a tcp:// port (a stream shows no gaps "
                                          "between bytes); use tcp_frame_gap instead");
        }
    } else {
        const std::string on_serial = " applies to tcp:// ports only (a serial device server); remove it";
        if (line.tcp_frame_gap.has_value()) sink.error(line.tcp_frame_gap, "tcp_frame_gap" + on_serial);
        if (line.connect_timeout.has_value()) sink.error(line.connect_timeout, "connect_timeout" + on_serial);
        if (!line.reconnect_backoff.absent()) {
            sink.error(line.reconnect_backoff, "reconnect_backoff" + on_serial + " (serial ports reopen on offline_backoff)");
        }
    }
    check_range(sink, line.request_gap, LineConfig::request_gap_range);
    check_range(sink, line.connect_timeout, LineConfig::connect_timeout_range);
    check_backoff(sink, line.reconnect_backoff, LineConfig{}.reconnect_backoff);
}

/// `port`: an absolute device path or tcp://host:port.
void check_port(const RawLine& line, DiagnosticSink& sink) {
    if (!require(sink, line.port, "the serial device path, e.g. /dev/ttyUSB0, or tcp://host:port")) return;
    if (is_tcp_port(*line.port)) {
        const auto endpoint = parse_tcp_port(*line.port);
        if (!endpoint) sink.error(line.port, endpoint.error);
        return;
    }
    if (!std::filesystem::path(*line.port).is_absolute()) {
        sink.error(line.port, "'" + *line.port +
                                  "' is not an absolute path; expected the serial device path, e.g. /dev/ttyUSB0 "
                                  "or /dev/serial/by-id/..., or tcp://host:port for a serial device server");
    }
}

}  // namespace

void validate_lines(const RawConfig& raw, DiagnosticSink& sink) {
    for (const auto& line : raw.lines.items) {
        if (!line.ok()) {
            continue;
        }
        if (require(sink, line.name, "a line name such as line-a")) {
            check_name(sink, line.name);
        }
        check_port(line, sink);
        check_transport(line, sink);
        check_serial(line, sink);
        check_timing(line, sink);
        if (line.broadcast_unit.has_value()) {
            check_range(sink, line.broadcast_unit, unit_id_range);
        }
        check_range(sink, line.broadcast_share, LineConfig::broadcast_share_range);
        validate_devices(line, sink);
    }
}

}  // namespace fieldbridge::config
