#include "daemon/watchdog.hpp"

#include <algorithm>

namespace fieldbridge::daemon {

std::optional<std::chrono::microseconds> watchdog_ping_interval(
    std::optional<std::chrono::microseconds> timeout) noexcept {
    if (!timeout || timeout->count() <= 0) {
        return std::nullopt;
    }
    return std::max(*timeout / 2, min_watchdog_ping_interval);
}

}  // namespace fieldbridge::daemon
