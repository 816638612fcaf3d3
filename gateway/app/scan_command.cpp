#include "app/scan_command.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <filesystem>
#include <memory>
#include <ostream>
#include <string_view>
#include <vector>

#include "config/config.hpp"
#include "config/device_definition.hpp"
#include "daemon/exit_codes.hpp"
#include "engine/posix_serial_port.hpp"
#include "engine/tcp_stream_port.hpp"
#include "scan/line_link.hpp"
#include "scan/line_scanner.hpp"
#include "scan/scan_report.hpp"

namespace fieldbridge::app {

namespace {

/// The widest device address range: EXCD203MB takes 1-254 (seed 002 section 5).
constexpr unsigned max_scan_address = 254;
constexpr unsigned max_timeout_ms = 10000;
/// A device server on the cell's network answers a connect within milliseconds.
constexpr std::chrono::milliseconds scan_connect_timeout{2000};

[[nodiscard]] engine::LogSink log_to(std::ostream& err, std::optional<config::LogLevel> level) {
    engine::LogSink sink;
    sink.min_level = level && *level <= core::LogLevel::debug ? core::LogLevel::debug : core::LogLevel::warning;
    sink.write = [&err](engine::LogLevel l, std::string_view message) {
        err << "fieldbridge scan: " << engine::to_string(l) << ": " << message << '\n';
    };
    return sink;
}

[[nodiscard]] engine::LineTimingConfig timing_of(const ScanOptions& o) {
    engine::LineTimingConfig t;
    t.baud = o.baud;
    t.data_bits = 8;
    t.parity = o.parity != core::Parity::none;
    t.stop_bits = o.stop_bits;
    t.response_timeout = std::chrono::milliseconds{o.timeout_ms};
    t.ascii_frame_timeout = std::chrono::milliseconds{o.timeout_ms};
    t.local_echo = o.local_echo;
    // The gateway's defaults (docs/configuration.md, lines[]): byte timeout 5 ms, or
    // 3.5 characters where that is longer (below 9600 bit/s).
    const engine::LineTiming wire(t.format(), t.inter_frame);
    t.byte_timeout = std::max<engine::Duration>(std::chrono::milliseconds{5}, wire.t3_5());
    // Through a serial device server: the gateway's tcp_frame_gap default, the same figure.
    t.stream = config::is_tcp_port(o.port);
    t.frame_gap = t.byte_timeout;
    return t;
}

[[nodiscard]] std::string format_of(const ScanOptions& o) {
    return std::to_string(o.baud) + " bit/s, 8" + std::string(1, core::parity_letter(o.parity)) + std::to_string(o.stop_bits);
}

/// The identify reads of the definitions in @p dirs (the defaults when empty). A
/// definition with problems is skipped and each problem reported on @p err: the scan
/// still runs.
[[nodiscard]] std::vector<scan::DefinitionIdentify> identify_reads(const std::vector<std::string>& dirs,
                                                                   std::ostream& err) {
    std::vector<std::filesystem::path> paths(dirs.begin(), dirs.end());
    if (paths.empty()) {
        paths.assign(config::default_definition_dirs.begin(), config::default_definition_dirs.end());
    }
    std::vector<config::Diagnostic> problems;
    const auto definitions = config::load_definitions(paths, problems);
    for (const auto& problem : problems) {
        err << "fieldbridge scan: skipping a device definition: " << problem.to_string() << '\n';
    }
    std::vector<scan::DefinitionIdentify> reads;
    for (const auto& definition : definitions) {
        if (definition.identify) {
            reads.push_back(scan::DefinitionIdentify{definition.name, *definition.identify});
        }
    }
    return reads;
}

}  // namespace

ScanCommand::ScanCommand(std::ostream& out, std::ostream& err) : out_(out), err_(err) {}

std::string ScanCommand::description() const {
    return "Find the Modbus-RTU and WTEC ASCII devices on a serial line and print a configuration snippet "
           "(stop a gateway using the port first)";
}

void ScanCommand::define(CLI::App& command) {
    command
        .add_option("-p,--port", options_.port,
                    "Serial port to scan, e.g. /dev/ttyUSB0, or tcp://HOST:PORT of a serial device server")
        ->type_name("DEV|tcp://HOST:PORT")
        ->required();
    std::vector<std::uint32_t> bauds(config::LineConfig::standard_bauds.begin(),
                                     config::LineConfig::standard_bauds.end());
    command.add_option("-b,--baud", options_.baud, "Bit rate of the line")
        ->type_name("N")
        ->check(CLI::IsMember(bauds))
        ->capture_default_str();
    command.add_option("--parity", parity_text_, "Parity: N (none), E (even) or O (odd)")
        ->type_name("N|E|O")
        ->check(CLI::IsMember({"N", "E", "O"}, CLI::ignore_case))
        ->capture_default_str();
    command.add_option("--stop-bits", options_.stop_bits, "Stop bits")
        ->type_name("1|2")
        ->check(CLI::IsMember({1U, 2U}))
        ->capture_default_str();
    command.add_option("--from", options_.first, "First address to probe")
        ->type_name("A")
        ->check(CLI::Range(1U, max_scan_address))
        ->capture_default_str();
    command.add_option("--to", options_.last, "Last address to probe (EXCD203MB addresses go up to 254)")
        ->type_name("B")
        ->check(CLI::Range(1U, max_scan_address))
        ->capture_default_str();
    command.add_option("--timeout", options_.timeout_ms, "Reply timeout per request in milliseconds")
        ->type_name("MS")
        ->check(CLI::Range(1U, max_timeout_ms))
        ->capture_default_str();
    command.add_flag("--local-echo", options_.local_echo,
                     "The adapter echoes what it sends (2-wire without echo suppression): discard the echo");
    command.add_flag("--rs485", options_.rs485, "Use the kernel RS-485 mode (TIOCSRS485) of the port");
    command.add_option("--definitions", options_.definition_dirs,
                       "Directory of device definitions whose identify reads name what is found (repeatable; "
                       "default /etc/fieldbridge/devices, /usr/share/fieldbridge/devices)")
        ->type_name("DIR");
}

int ScanCommand::run(std::optional<config::LogLevel> log_level) {
    // Validated by the option's check, so the letter is N, E or O in either case.
    options_.parity = core::parse_parity_letter(parity_text_.front()).value_or(core::Parity::none);
    if (options_.first > options_.last) {
        err_ << "fieldbridge scan: --from " << options_.first << " is above --to " << options_.last
             << "; give the first address, then the last\n";
        return daemon::exit_usage;
    }
    engine::SerialSettings settings;
    settings.path = options_.port;
    settings.baud = options_.baud;
    settings.parity = options_.parity;
    settings.stop_bits = options_.stop_bits;
    settings.rs485 = options_.rs485;
    if (config::is_tcp_port(options_.port)) {
        const auto endpoint = config::parse_tcp_port(options_.port);
        if (!endpoint) {
            err_ << "fieldbridge scan: --port " << endpoint.error << '\n';
            return daemon::exit_usage;
        }
        if (options_.rs485 || options_.local_echo) {
            err_ << "fieldbridge scan: " << (options_.rs485 ? "--rs485" : "--local-echo")
                 << " does not apply to a tcp:// port: the serial device server drives the line; leave it out\n";
            return daemon::exit_usage;
        }
        settings.tcp = engine::StreamEndpoint{endpoint.value->host, endpoint.value->port, scan_connect_timeout};
    }

    std::unique_ptr<engine::SerialPort> port;
    if (settings.tcp) {
        port = std::make_unique<engine::TcpStreamPort>(settings, engine::ConnectWait::block);
    } else {
        port = std::make_unique<engine::PosixSerialPort>(settings);
    }
    try {
        port->open();
    } catch (const engine::SerialPortError& error) {
        err_ << "fieldbridge scan: " << error.what()
             << ". The scan needs the port to itself: stop a fieldbridge gateway (or any other program) using it.\n";
        return exit_port_error;
    }

    const auto definitions = identify_reads(options_.definition_dirs, err_);
    err_ << "fieldbridge scan: " << options_.port << " at " << format_of(options_) << ", addresses "
         << options_.first << "-" << options_.last << ", timeout " << options_.timeout_ms << " ms\n";
    scan::ScanResult result;
    try {
        scan::LineLink link(*port, timing_of(options_), log_to(err_, log_level));
        scan::LineScanner scanner(
            link, scan::ScanRange{static_cast<std::uint8_t>(options_.first), static_cast<std::uint8_t>(options_.last)},
            [this](const std::string& text) { err_ << "fieldbridge scan: " << text << '\n'; }, definitions);
        result = scanner.run();
    } catch (const engine::SerialPortError& error) {
        err_ << "fieldbridge scan: the scan stopped: " << error.what() << '\n';
        return exit_port_error;
    }

    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(result.stats.elapsed).count();
    err_ << "fieldbridge scan: done in " << ms << " ms, " << result.stats.requests << " requests, "
         << result.stats.timeouts << " without reply: " << result.devices.size()
         << (result.devices.size() == 1 ? " device" : " devices") << " found\n";
    if (result.devices.empty()) {
        err_ << "fieldbridge scan: no device answered at addresses " << options_.first << "-" << options_.last
             << " on " << options_.port << "; check the bit rate, parity and stop bits (" << format_of(options_)
             << "), the wiring (A/B swapped?), termination, and the address range\n";
        return exit_nothing_found;
    }
    out_ << scan::config_snippet(
        scan::ScannedLine{options_.port, options_.baud, options_.parity, options_.stop_bits}, result.devices);
    out_.flush();
    return daemon::exit_ok;
}

}  // namespace fieldbridge::app
