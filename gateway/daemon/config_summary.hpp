#pragma once
/// @file config_summary.hpp
/// Short descriptions of a configuration for `--check-config`, logs and STATUS=.

#include <string>

#include "config/config.hpp"

namespace fieldbridge::daemon {

/// "2 lines, 4 devices", followed by ", 1 upstream" when upstreams are configured.
[[nodiscard]] std::string describe_inventory(const config::Config& config);

/// describe_inventory() followed by ", MQTT enabled" or ", MQTT disabled", and by the
/// Sparkplug group and edge node when the sparkplug section is present.
[[nodiscard]] std::string describe_config(const config::Config& config);

}  // namespace fieldbridge::daemon
