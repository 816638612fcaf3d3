#pragma once
/// @file logging.hpp
/// The gateway's logger: spdlog to stderr, with journald priority prefixes when
/// stderr is connected to the journal, a human format otherwise. Every message is
/// written in the escape form of core/log_text.hpp (control characters and bytes
/// that are not UTF-8 as `\n`, `\xHH`...): one message is one line, whatever text
/// from outside it carries.
///
/// The logger is created once in main() and handed to every component as a
/// `std::shared_ptr<spdlog::logger>`; nothing registers it in spdlog's global
/// registry or relies on spdlog's default logger, so tests build their own logger
/// over a string sink.

#include <spdlog/common.h>
#include <spdlog/formatter.h>
#include <spdlog/logger.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "config/config.hpp"

namespace fieldbridge::daemon {

enum class LogFormat {
    /// "<6>message": journald adds time, unit and PID itself, and files the line
    /// under the priority of the prefix.
    journal,
    /// "2024-05-01 12:00:00.123 [info] message" for a terminal or a log file.
    human,
};

/// True when @p journal_stream (the value of JOURNAL_STREAM, "<device>:<inode>" in
/// decimal, see systemd.exec(5)) names the file with @p device and @p inode.
[[nodiscard]] bool journal_stream_matches(std::string_view journal_stream, std::uint64_t device,
                                          std::uint64_t inode) noexcept;

/// LogFormat::journal when @p journal_stream (null when unset) matches what @p fd
/// is open on, as systemd.exec(5) recommends: a child that inherited the variable
/// but writes elsewhere (a terminal, a redirect) gets the human format.
[[nodiscard]] LogFormat detect_log_format(const char* journal_stream, int fd) noexcept;

/// The pattern formatter for @p format ("%J%v" or the human pattern), whose %v is
/// the escaped message.
[[nodiscard]] std::unique_ptr<spdlog::formatter> make_formatter(LogFormat format);

/// A logger named @p name writing to @p sink in @p format. Not registered in
/// spdlog's registry.
[[nodiscard]] std::shared_ptr<spdlog::logger> make_logger(std::string name, spdlog::sink_ptr sink, LogFormat format);

/// The spdlog level of a configured level (`warning` is spdlog's `warn`).
[[nodiscard]] spdlog::level::level_enum to_spdlog_level(config::LogLevel level) noexcept;

}  // namespace fieldbridge::daemon
