#include "daemon/systemd_service_manager.hpp"

#include <systemd/sd-daemon.h>

#include <cstdint>
#include <string>
#include <system_error>
#include <utility>

namespace fieldbridge::daemon {

SystemdServiceManager::SystemdServiceManager(std::shared_ptr<spdlog::logger> logger) : logger_(std::move(logger)) {}

void SystemdServiceManager::notify(std::string_view state) noexcept {
    try {
        const std::string text(state);
        // sd_notify returns 0 when NOTIFY_SOCKET is unset (nothing to do), > 0 when
        // sent, < 0 (-errno) when the socket exists but sending failed.
        const int result = sd_notify(0, text.c_str());
        if (result < 0) {
            if (!failing_) {
                logger_->warn("cannot notify the service manager ({}): {}; systemd may consider the service "
                                 "not ready or hung; check NOTIFY_SOCKET and NotifyAccess= in the unit",
                                 text.substr(0, text.find('\n')), std::generic_category().message(-result));
            }
            failing_ = true;
        } else if (failing_) {
            logger_->info("notifications to the service manager work again");
            failing_ = false;
        }
    } catch (...) {
        // A try/catch wall: allocation or logging failures must not escape a noexcept
        // seam called from every loop duty.
        failing_ = true;
    }
}

std::optional<std::chrono::microseconds> SystemdServiceManager::watchdog_timeout() const {
    std::uint64_t usec = 0;
    const int result = sd_watchdog_enabled(0, &usec);
    if (result < 0) {
        logger_->warn("ignoring the watchdog settings from systemd (WATCHDOG_USEC / WATCHDOG_PID): {}; "
                         "the watchdog stays off",
                         std::generic_category().message(-result));
        return std::nullopt;
    }
    if (result == 0 || usec == 0) {
        return std::nullopt;
    }
    return std::chrono::microseconds{static_cast<std::chrono::microseconds::rep>(usec)};
}

}  // namespace fieldbridge::daemon
