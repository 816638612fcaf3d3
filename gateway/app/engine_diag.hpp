#pragma once
/// @file engine_diag.hpp
/// The line and device counters of `<prefix>/diag` (spec §7 observability): per line
/// the master's counters, latency percentiles, utilisation since the previous
/// snapshot and queue depth per priority class; per device its scheduler counters.
/// Keeps the previous busy time of each line to compute utilisation. Loop thread.
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "engine/engine.hpp"

namespace fieldbridge::app {

class EngineDiag {
public:
    /// {"lines": [...]} for @p engine at @p now.
    [[nodiscard]] nlohmann::json collect(const engine::Engine& engine, engine::TimePoint now);

private:
    struct Busy {
        engine::Duration busy{};
        engine::TimePoint at{};
    };
    std::map<std::string, Busy, std::less<>> last_;
};

}  // namespace fieldbridge::app
