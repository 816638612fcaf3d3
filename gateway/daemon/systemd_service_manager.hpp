#pragma once
/// @file systemd_service_manager.hpp
/// ServiceManager over libsystemd's sd_notify(3) and sd_watchdog_enabled(3).

#include <memory>

#include <spdlog/logger.h>

#include "daemon/service_manager.hpp"

namespace fieldbridge::daemon {

class SystemdServiceManager final : public ServiceManager {
public:
    /// @p logger receives a warning when a notification cannot be delivered.
    explicit SystemdServiceManager(std::shared_ptr<spdlog::logger> logger);

    /// sd_notify(0, state): the environment is kept, so that READY=1 can be sent
    /// again after every reload.
    void notify(std::string_view state) noexcept override;

    /// sd_watchdog_enabled(0, ...): enabled when WATCHDOG_USEC is set and
    /// WATCHDOG_PID is unset or names this process.
    [[nodiscard]] std::optional<std::chrono::microseconds> watchdog_timeout() const override;

private:
    std::shared_ptr<spdlog::logger> logger_;
    bool failing_ = false;  ///< the last notification failed (warn once per outage)
};

}  // namespace fieldbridge::daemon
