#pragma once
/// @file scan_command.hpp
/// `fieldbridge scan`: finds the devices on one serial line and prints a
/// configuration snippet for them (product spec section 7, discovery).
///
///     fieldbridge scan --port DEV [--baud N] [--parity N|E|O] [--stop-bits 1|2]
///                      [--from A] [--to B] [--timeout MS] [--local-echo] [--rs485]
///                      [--definitions DIR]...
///
/// The port must not be in use: stop a gateway running on it first. Progress and
/// errors go to the error stream, the snippet to the output stream.
/// Exit codes: 0 devices found, 1 nothing answered, 2 the port could not be opened
/// or failed, 64 usage error (as every fieldbridge usage error).

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "core/parity.hpp"
#include "daemon/command_line.hpp"

namespace fieldbridge::app {

/// Exit code when no device answered.
inline constexpr int exit_nothing_found = 1;
/// Exit code when the port cannot be opened or fails during the scan.
inline constexpr int exit_port_error = 2;

/// The scan's options with their defaults.
struct ScanOptions {
    std::string port;
    std::uint32_t baud = 115200;
    core::Parity parity = core::Parity::none;
    unsigned stop_bits = 1;
    unsigned first = 1;
    /// 247 is the last Modbus address; EXCD203MB (254) and WTEC (253) go further.
    unsigned last = 247;
    /// Reply timeout per request, Modbus and ASCII alike: short, since a device that
    /// is there answers within a few milliseconds (WTEC: within 50 ms, seed 003 1.1).
    unsigned timeout_ms = 50;
    bool local_echo = false;
    bool rs485 = false;
    /// Directories of device definitions whose `identify:` reads name generic devices;
    /// empty: the configuration's defaults (config::default_definition_dirs).
    std::vector<std::string> definition_dirs;
};

class ScanCommand final : public daemon::Subcommand {
public:
    /// @p out receives the snippet, @p err progress and errors.
    ScanCommand(std::ostream& out, std::ostream& err);

    [[nodiscard]] std::string name() const override { return "scan"; }
    [[nodiscard]] std::string description() const override;
    void define(CLI::App& command) override;
    [[nodiscard]] int run(std::optional<config::LogLevel> log_level) override;

    [[nodiscard]] const ScanOptions& options() const noexcept { return options_; }

private:
    std::ostream& out_;
    std::ostream& err_;
    ScanOptions options_;
    std::string parity_text_ = "N";
};

}  // namespace fieldbridge::app
