#pragma once
/// @file exit_codes.hpp
/// The process exit codes of `fieldbridge` (documented in docs/service.md).

namespace fieldbridge::daemon {

/// Normal end: `--check-config` found the file valid, `--version`, `--help`, or the
/// service stopped on SIGTERM/SIGINT.
inline constexpr int exit_ok = 0;
/// A runtime failure after the configuration was accepted (a component could not
/// start, or reported a fatal error). systemd's `Restart=on-failure` restarts it.
inline constexpr int exit_failure = 1;
/// The configuration file is missing, unreadable or invalid (spec section 8), or the
/// sockets systemd passed do not match its modbus_tcp.listen (socket activation). The
/// unit file lists it in `RestartPreventExitStatus=`: restarting cannot help.
inline constexpr int exit_config_error = 2;
/// Wrong command line (sysexits.h EX_USAGE); CLI11's own codes (105-115) are mapped
/// to it so that scripts see one stable value.
inline constexpr int exit_usage = 64;

}  // namespace fieldbridge::daemon
