#include <doctest/doctest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <sys/stat.h>

#include <cctype>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>

#include "daemon/journal_priority.hpp"
#include "daemon/logging.hpp"

namespace daemon_ns = fieldbridge::daemon;
using fieldbridge::config::LogLevel;
using daemon_ns::LogFormat;

namespace {

struct Captured {
    std::ostringstream text;
    std::shared_ptr<spdlog::logger> logger;

    explicit Captured(LogFormat format)
        : logger(daemon_ns::make_logger("test", std::make_shared<spdlog::sinks::ostream_sink_st>(text), format)) {
        logger->set_level(spdlog::level::trace);
    }
};

/// True when @p text matches @p shape, where '9' stands for any digit and every
/// other character for itself (std::regex trips GCC 12's -Wmaybe-uninitialized
/// under the sanitizers).
[[nodiscard]] bool matches_shape(const std::string& text, const std::string& shape) {
    if (text.size() != shape.size()) {
        return false;
    }
    for (std::size_t i = 0; i < text.size(); ++i) {
        const bool ok = shape[i] == '9' ? std::isdigit(static_cast<unsigned char>(text[i])) != 0 : text[i] == shape[i];
        if (!ok) {
            return false;
        }
    }
    return true;
}

}  // namespace

TEST_CASE("journal priorities follow sd-daemon(3)") {
    CHECK(daemon_ns::journal_priority(spdlog::level::critical) == 2);  // SD_CRIT
    CHECK(daemon_ns::journal_priority(spdlog::level::err) == 3);       // SD_ERR
    CHECK(daemon_ns::journal_priority(spdlog::level::warn) == 4);      // SD_WARNING
    CHECK(daemon_ns::journal_priority(spdlog::level::info) == 6);      // SD_INFO
    CHECK(daemon_ns::journal_priority(spdlog::level::debug) == 7);     // SD_DEBUG
    CHECK(daemon_ns::journal_priority(spdlog::level::trace) == 7);
}

TEST_CASE("the journal format prefixes every message with its priority, through the %J flag") {
    Captured log(LogFormat::journal);
    log.logger->error("port {} vanished", "/dev/ttyUSB0");
    log.logger->warn("retrying");
    log.logger->info("ready");
    log.logger->debug("poll");
    log.logger->trace("bytes");
    log.logger->critical("internal error");
    CHECK(log.text.str() ==
          "<3>port /dev/ttyUSB0 vanished\n<4>retrying\n<6>ready\n<7>poll\n<7>bytes\n<2>internal error\n");
}

TEST_CASE("the %J flag works inside any pattern") {
    std::ostringstream text;
    auto logger = std::make_shared<spdlog::logger>("x", std::make_shared<spdlog::sinks::ostream_sink_st>(text));
    auto formatter = std::make_unique<spdlog::pattern_formatter>();
    formatter->add_flag<daemon_ns::JournalPriorityFlag>('J').set_pattern("[%J] %v");
    logger->set_formatter(std::move(formatter));
    logger->warn("w");
    CHECK(text.str() == "[<4>] w\n");
}

TEST_CASE("the human format carries time and level, and no priority prefix") {
    Captured log(LogFormat::human);
    log.logger->warn("line a: 3 timeouts");
    CHECK(matches_shape(log.text.str(), "9999-99-99 99:99:99.999 [warning] line a: 3 timeouts\n"));
    CHECK_FALSE(matches_shape("2024-01-01 12:00:00.123 [warning] x\n", "9999-99-99 99:99:99.999 [warning] y\n"));
}

TEST_CASE("a message carrying control characters stays one line in both formats (issue 24 item 4)") {
    // As the MQTT bridge logged an op from a command: the op is from outside.
    const std::string op = "x\n2026-01-01 00:00:00.000 [critical] FORGED\x1b[2J";
    for (const auto format : {LogFormat::journal, LogFormat::human}) {
        Captured log(format);
        log.logger->warn("MQTT: command 1 '{}' to gripper-1: unknown_op", op);
        const std::string text = log.text.str();
        CHECK(text.find('\n') == text.size() - 1);  // the line's own end only
        CHECK(text.find('\x1b') == std::string::npos);
        CHECK(text.find("'x\\n2026-01-01 00:00:00.000 [critical] FORGED\\x1B[2J' to gripper-1") !=
              std::string::npos);
    }
}

TEST_CASE("the log level filters messages") {
    Captured log(LogFormat::journal);
    log.logger->set_level(daemon_ns::to_spdlog_level(LogLevel::warning));
    log.logger->info("hidden");
    log.logger->warn("shown");
    CHECK(log.text.str() == "<4>shown\n");
}

TEST_CASE("JOURNAL_STREAM is matched against device and inode") {
    CHECK(daemon_ns::journal_stream_matches("8:12345", 8, 12345));
    CHECK_FALSE(daemon_ns::journal_stream_matches("8:12345", 8, 12346));
    CHECK_FALSE(daemon_ns::journal_stream_matches("9:12345", 8, 12345));
    CHECK(daemon_ns::journal_stream_matches("18446744073709551615:1", 18446744073709551615ULL, 1));
    CHECK_FALSE(daemon_ns::journal_stream_matches("18446744073709551616:1", 0, 1));  // overflow
    CHECK_FALSE(daemon_ns::journal_stream_matches("", 0, 0));
    CHECK_FALSE(daemon_ns::journal_stream_matches("8", 8, 0));
    CHECK_FALSE(daemon_ns::journal_stream_matches("8:", 8, 0));
    CHECK_FALSE(daemon_ns::journal_stream_matches(":5", 0, 5));
    CHECK_FALSE(daemon_ns::journal_stream_matches("8:5x", 8, 5));
    CHECK_FALSE(daemon_ns::journal_stream_matches("-8:5", 8, 5));
    CHECK_FALSE(daemon_ns::journal_stream_matches(" 8:5", 8, 5));
}

TEST_CASE("the journal format is chosen only when the fd is the journal stream") {
    std::FILE* file = std::tmpfile();
    REQUIRE(file != nullptr);
    const int fd = ::fileno(file);
    struct stat info {};
    REQUIRE(::fstat(fd, &info) == 0);
    const auto matching = std::to_string(info.st_dev) + ':' + std::to_string(info.st_ino);
    const auto other = std::to_string(info.st_dev) + ':' + std::to_string(info.st_ino + 1);

    CHECK(daemon_ns::detect_log_format(matching.c_str(), fd) == LogFormat::journal);
    CHECK(daemon_ns::detect_log_format(other.c_str(), fd) == LogFormat::human);
    CHECK(daemon_ns::detect_log_format(nullptr, fd) == LogFormat::human);
    std::fclose(file);
    CHECK(daemon_ns::detect_log_format(matching.c_str(), -1) == LogFormat::human);
}

TEST_CASE("log levels: config spelling and spdlog mapping") {
    CHECK(fieldbridge::core::parse<LogLevel>("trace") == LogLevel::trace);
    CHECK(fieldbridge::core::parse<LogLevel>("debug") == LogLevel::debug);
    CHECK(fieldbridge::core::parse<LogLevel>("info") == LogLevel::info);
    CHECK(fieldbridge::core::parse<LogLevel>("warning") == LogLevel::warning);
    CHECK(fieldbridge::core::parse<LogLevel>("error") == LogLevel::error);
    CHECK_FALSE(fieldbridge::core::parse<LogLevel>("warn").has_value());
    CHECK_FALSE(fieldbridge::core::parse<LogLevel>("INFO").has_value());
    CHECK_FALSE(fieldbridge::core::parse<LogLevel>("").has_value());

    CHECK(daemon_ns::to_spdlog_level(LogLevel::trace) == spdlog::level::trace);
    CHECK(daemon_ns::to_spdlog_level(LogLevel::debug) == spdlog::level::debug);
    CHECK(daemon_ns::to_spdlog_level(LogLevel::info) == spdlog::level::info);
    CHECK(daemon_ns::to_spdlog_level(LogLevel::warning) == spdlog::level::warn);
    CHECK(daemon_ns::to_spdlog_level(LogLevel::error) == spdlog::level::err);
}
