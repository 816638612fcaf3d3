#pragma once
/// @file journal_priority.hpp
/// The "<N>" prefix journald reads from a service's stderr (sd-daemon(3)): each
/// line that starts with it is stored with syslog priority N.

#include <spdlog/common.h>
#include <spdlog/pattern_formatter.h>

#include <ctime>
#include <memory>

namespace fieldbridge::daemon {

/// sd-daemon(3) priorities: SD_CRIT "<2>", SD_ERR "<3>", SD_WARNING "<4>",
/// SD_INFO "<6>", SD_DEBUG "<7>". spdlog's trace has no syslog equivalent and is
/// stored as debug; `off` (never logged) maps to info.
[[nodiscard]] int journal_priority(spdlog::level::level_enum level) noexcept;

/// spdlog pattern flag that writes "<N>" for the message's level (see
/// make_formatter() in logging.hpp: it is registered as %J).
class JournalPriorityFlag final : public spdlog::custom_flag_formatter {
public:
    void format(const spdlog::details::log_msg& msg, const std::tm& tm_time, spdlog::memory_buf_t& dest) override;
    [[nodiscard]] std::unique_ptr<spdlog::custom_flag_formatter> clone() const override;
};

}  // namespace fieldbridge::daemon
