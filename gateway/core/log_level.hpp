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
template <>
struct Names<LogLevel> {
    static constexpr const auto& table = log_level_names;
};

}  // namespace fieldbridge::core
