#include <doctest/doctest.h>
#include <spdlog/sinks/ostream_sink.h>

#include <memory>
#include <sstream>
#include <string>

#include "app/engine_component.hpp"

namespace fe = fieldbridge::engine;

namespace {

struct Logged {
    std::ostringstream text;
    std::shared_ptr<spdlog::logger> logger = std::make_shared<spdlog::logger>(
        "test", std::make_shared<spdlog::sinks::ostream_sink_st>(text));
};

}  // namespace

TEST_CASE("the engine's log sink lets through what the daemon's logger would log, at each call") {
    Logged logged;
    logged.logger->set_level(spdlog::level::info);
    const fe::LogSink sink = fieldbridge::app::engine_log_sink(logged.logger);

    // A debug line of the engine (one per state change of every transaction) is not
    // even built while the logger is at info.
    CHECK_FALSE(sink.enabled(fe::LogLevel::debug));
    CHECK(sink.enabled(fe::LogLevel::info));
    CHECK(sink.enabled(fe::LogLevel::error));
    sink(fe::LogLevel::debug, "dropped");
    sink(fe::LogLevel::warning, "line a: kept");
    CHECK(logged.text.str().find("dropped") == std::string::npos);
    CHECK(logged.text.str().find("line a: kept") != std::string::npos);

    // A reload that lowers the level reaches the sink already handed out.
    logged.logger->set_level(spdlog::level::debug);
    CHECK(sink.enabled(fe::LogLevel::debug));
    sink(fe::LogLevel::debug, "now shown");
    CHECK(logged.text.str().find("now shown") != std::string::npos);

    logged.logger->set_level(spdlog::level::err);
    CHECK_FALSE(sink.enabled(fe::LogLevel::warning));
    CHECK(sink.enabled(fe::LogLevel::error));
}

TEST_CASE("a sink's accepts decides over min_level; without write nothing is enabled") {
    int written = 0;
    fe::LogSink sink{[&](fe::LogLevel, std::string_view) { ++written; }, fe::LogLevel::error,
                     [](fe::LogLevel level) { return level == fe::LogLevel::debug; }};
    CHECK(sink.enabled(fe::LogLevel::debug));
    CHECK_FALSE(sink.enabled(fe::LogLevel::error));
    sink(fe::LogLevel::error, "x");
    sink(fe::LogLevel::debug, "y");
    CHECK(written == 1);

    const fe::LogSink silent{{}, fe::LogLevel::debug, [](fe::LogLevel) { return true; }};
    CHECK_FALSE(silent.enabled(fe::LogLevel::error));
}
