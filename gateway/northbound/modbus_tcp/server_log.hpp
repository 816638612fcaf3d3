#pragma once
/// @file server_log.hpp
/// Formats a Modbus TCP server message only when its level is enabled.
#include <utility>

#include <fmt/format.h>

#include "engine/line_log.hpp"

namespace fieldbridge::northbound::modbus_tcp {

template <class... Args>
void log(const engine::LogSink& sink, engine::LogLevel level, fmt::format_string<Args...> format,
         Args&&... args) {
    if (sink.enabled(level)) sink(level, fmt::format(format, std::forward<Args>(args)...));
}

}  // namespace fieldbridge::northbound::modbus_tcp
