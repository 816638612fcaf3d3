#pragma once
/// @file service_manager.hpp
/// The seam between the daemon and the service manager (systemd). The daemon only
/// talks to this interface; main() injects SystemdServiceManager, unit tests a fake
/// that records what would have been sent.

#include <chrono>
#include <optional>
#include <string_view>

namespace fieldbridge::daemon {

class ServiceManager {
public:
    ServiceManager() = default;
    ServiceManager(const ServiceManager&) = delete;
    ServiceManager& operator=(const ServiceManager&) = delete;
    ServiceManager(ServiceManager&&) = delete;
    ServiceManager& operator=(ServiceManager&&) = delete;
    virtual ~ServiceManager() = default;

    /// Sends a state change: newline-separated assignments as in sd_notify(3), e.g.
    /// "READY=1\nSTATUS=2 lines, 4 devices". A no-op when not started by a service
    /// manager (NOTIFY_SOCKET unset). Never throws: failing to notify must not take
    /// the gateway down.
    virtual void notify(std::string_view state) noexcept = 0;

    /// The watchdog timeout the manager expects pings within (WatchdogSec=), or
    /// nullopt when the watchdog is not enabled for this process.
    [[nodiscard]] virtual std::optional<std::chrono::microseconds> watchdog_timeout() const = 0;
};

}  // namespace fieldbridge::daemon
