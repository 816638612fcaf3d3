#include "daemon/journal_priority.hpp"

#include <spdlog/details/log_msg.h>

namespace fieldbridge::daemon {

int journal_priority(spdlog::level::level_enum level) noexcept {
    // Values of LOG_CRIT .. LOG_DEBUG (syslog.h), which SD_CRIT .. SD_DEBUG wrap.
    switch (level) {
        case spdlog::level::critical:
            return 2;
        case spdlog::level::err:
            return 3;
        case spdlog::level::warn:
            return 4;
        case spdlog::level::info:
            return 6;
        case spdlog::level::debug:
        case spdlog::level::trace:
            return 7;
        case spdlog::level::off:
        case spdlog::level::n_levels:
            break;
    }
    return 6;
}

void JournalPriorityFlag::format(const spdlog::details::log_msg& msg, const std::tm& /*tm_time*/,
                                 spdlog::memory_buf_t& dest) {
    const char prefix[] = {'<', static_cast<char>('0' + journal_priority(msg.level)), '>'};
    dest.append(prefix, prefix + sizeof prefix);
}

std::unique_ptr<spdlog::custom_flag_formatter> JournalPriorityFlag::clone() const {
    return std::make_unique<JournalPriorityFlag>();
}

}  // namespace fieldbridge::daemon
