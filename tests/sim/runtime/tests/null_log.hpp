#pragma once
// A logger that discards everything, for the runtime's unit tests.
#include <memory>

#include <spdlog/logger.h>
#include <spdlog/sinks/null_sink.h>

namespace fieldbridge::sim::runtime::test {

inline std::shared_ptr<spdlog::logger> null_log() {
    return std::make_shared<spdlog::logger>("test", std::make_shared<spdlog::sinks::null_sink_mt>());
}

}  // namespace fieldbridge::sim::runtime::test
