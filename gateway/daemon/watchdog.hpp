#pragma once
/// @file watchdog.hpp
/// How often the loop pings the systemd watchdog.

#include <chrono>
#include <optional>

namespace fieldbridge::daemon {

/// The shortest ping period used, whatever WatchdogSec= says: a timeout this
/// small cannot be met by any real process, and pinging faster would only burn CPU.
inline constexpr std::chrono::microseconds min_watchdog_ping_interval = std::chrono::milliseconds{1};

/// Ping period for a watchdog @p timeout: half of it, as sd_watchdog_enabled(3)
/// recommends, so that one late ping still arrives in time; never below
/// min_watchdog_ping_interval. nullopt (watchdog off) stays nullopt.
[[nodiscard]] std::optional<std::chrono::microseconds> watchdog_ping_interval(
    std::optional<std::chrono::microseconds> timeout) noexcept;

}  // namespace fieldbridge::daemon
