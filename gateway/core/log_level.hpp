#pragma once
/// @file log_level.hpp
/// Log levels, in increasing severity: the config's `gateway.log_level`, the
/// `--log-level` option and the engine's log seam (engine/line_log.hpp) use this one enum.

#include <cstdint>
#include <optional>
#include <string_view>

#include "core/names.hpp"

namespace fieldbridge::core {

enum class LogLevel : std::uint8_t { trace, debug, info, warning, error };

inline constexpr NameTable<LogLevel, 5> log_level_names{{
    {"trace", LogLevel::trace},
    {"debug", LogLevel::debug},
    {"info", LogLevel::info},
    {"warning", LogLevel::warning},
    {"error", LogLevel::error},
}};

/// "trace", "debug", "info", "warning", "error".
[[nodiscard]] constexpr std::string_view to_string(LogLevel level) noexcept {
    return name_in(log_level_names, level);
}
[[nodiscard]] constexpr std::optional<LogLevel> parse_log_level(std::string_view text) noexcept {
    return value_in(log_level_names, text);
}

}  // namespace fieldbridge::core
