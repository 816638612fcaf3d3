#include "daemon/logging.hpp"

#include <spdlog/pattern_formatter.h>
#include <sys/stat.h>

#include <array>
#include <charconv>
#include <utility>

#include "core/log_text.hpp"
#include "daemon/journal_priority.hpp"

namespace fieldbridge::daemon {

namespace {

constexpr char journal_flag = 'J';
/// spdlog's own message flag, replaced: no pattern can write a message unescaped.
constexpr char message_flag = 'v';
constexpr const char* journal_pattern = "%J%v";
constexpr const char* human_pattern = "%Y-%m-%d %H:%M:%S.%e [%l] %v";

/// Parses a whole decimal field; nullopt for empty text, other characters or overflow.
[[nodiscard]] std::optional<std::uint64_t> parse_decimal(std::string_view text) noexcept {
    std::uint64_t value = 0;
    const auto* end = text.data() + text.size();
    const auto [ptr, error] = std::from_chars(text.data(), end, value);
    if (text.empty() || error != std::errc{} || ptr != end) {
        return std::nullopt;
    }
    return value;
}

/// %v: the message in the escape form of core/log_text.hpp. Strings from outside
/// (MQTT topics and payloads, Modbus TCP peers, HTTP requests, upstream replies) reach
/// log messages at many call sites; escaping here, once, means none can forge a line
/// or send the operator's terminal an escape sequence.
class EscapedMessageFlag final : public spdlog::custom_flag_formatter {
public:
    void format(const spdlog::details::log_msg& msg, const std::tm& /*tm_time*/, spdlog::memory_buf_t& dest) override {
        const std::string_view text(msg.payload.data(), msg.payload.size());
        if (!core::needs_log_escape(text)) {
            dest.append(text.data(), text.data() + text.size());
            return;
        }
        const std::string escaped = core::escape_log_text(text);
        dest.append(escaped.data(), escaped.data() + escaped.size());
    }
    [[nodiscard]] std::unique_ptr<spdlog::custom_flag_formatter> clone() const override {
        return std::make_unique<EscapedMessageFlag>();
    }
};

}  // namespace

bool journal_stream_matches(std::string_view journal_stream, std::uint64_t device, std::uint64_t inode) noexcept {
    const auto colon = journal_stream.find(':');
    if (colon == std::string_view::npos) {
        return false;
    }
    const auto stream_device = parse_decimal(journal_stream.substr(0, colon));
    const auto stream_inode = parse_decimal(journal_stream.substr(colon + 1));
    return stream_device && stream_inode && *stream_device == device && *stream_inode == inode;
}

LogFormat detect_log_format(const char* journal_stream, int fd) noexcept {
    if (journal_stream == nullptr) {
        return LogFormat::human;
    }
    struct stat info {};
    if (::fstat(fd, &info) != 0) {
        return LogFormat::human;
    }
    return journal_stream_matches(journal_stream, static_cast<std::uint64_t>(info.st_dev),
                                  static_cast<std::uint64_t>(info.st_ino))
               ? LogFormat::journal
               : LogFormat::human;
}

std::unique_ptr<spdlog::formatter> make_formatter(LogFormat format) {
    auto formatter = std::make_unique<spdlog::pattern_formatter>();
    formatter->add_flag<JournalPriorityFlag>(journal_flag);
    formatter->add_flag<EscapedMessageFlag>(message_flag);
    formatter->set_pattern(format == LogFormat::journal ? journal_pattern : human_pattern);
    return formatter;
}

std::shared_ptr<spdlog::logger> make_logger(std::string name, spdlog::sink_ptr sink, LogFormat format) {
    auto logger = std::make_shared<spdlog::logger>(std::move(name), std::move(sink));
    logger->set_formatter(make_formatter(format));
    return logger;
}

spdlog::level::level_enum to_spdlog_level(config::LogLevel level) noexcept {
    switch (level) {
        case config::LogLevel::trace:
            return spdlog::level::trace;
        case config::LogLevel::debug:
            return spdlog::level::debug;
        case config::LogLevel::info:
            return spdlog::level::info;
        case config::LogLevel::warning:
            return spdlog::level::warn;
        case config::LogLevel::error:
            return spdlog::level::err;
    }
    return spdlog::level::info;
}

}  // namespace fieldbridge::daemon
