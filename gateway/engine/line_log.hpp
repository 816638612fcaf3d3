#pragma once
/// @file line_log.hpp
/// The log seam of the line engine: the scheduler and the line master report through
/// an injected sink, never a global logger, so tests can capture and assert on it
/// and the daemon can route it to spdlog / journald.

#include <cstdint>
#include <functional>
#include <string_view>

#include "core/log_level.hpp"

namespace fieldbridge::engine {

using core::LogLevel;
using core::to_string;

/// Receives one finished message per call. Messages are only built when
/// enabled(level) is true, so a debug transition log costs nothing when off.
struct LogSink {
    std::function<void(LogLevel, std::string_view)> write;
    LogLevel min_level = LogLevel::info;
    /// When set, decides instead of min_level, at each call: the daemon's sink asks
    /// its logger, whose level a reload may change. Without it a sink that let every
    /// level through would have the engine build a debug line per state change of
    /// every transaction only for the logger to drop it.
    std::function<bool(LogLevel)> accepts = {};

    [[nodiscard]] bool enabled(LogLevel level) const noexcept {
        if (!write) return false;
        return accepts ? accepts(level) : level >= min_level;
    }
    void operator()(LogLevel level, std::string_view message) const {
        if (enabled(level)) write(level, message);
    }
};

}  // namespace fieldbridge::engine
