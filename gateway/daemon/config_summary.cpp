#include "daemon/config_summary.hpp"

#include <cstddef>

#include "daemon/status_board.hpp"

namespace fieldbridge::daemon {

std::string describe_inventory(const config::Config& config) {
    std::size_t devices = 0;
    for (const auto& line : config.lines) {
        devices += line.devices.size();
    }
    std::string text = count_of(config.lines.size(), "line", "lines") + ", " + count_of(devices, "device", "devices");
    if (!config.upstreams.empty()) {
        text += ", " + count_of(config.upstreams.size(), "upstream", "upstreams");
    }
    return text;
}

std::string describe_config(const config::Config& config) {
    std::string text = describe_inventory(config) + (config.mqtt.enabled ? ", MQTT enabled" : ", MQTT disabled");
    if (config.sparkplug) {
        text += ", Sparkplug B enabled (group " + config.sparkplug->group_id + ", edge node " +
                config.sparkplug->edge_node_id + ")";
    }
    return text;
}

}  // namespace fieldbridge::daemon
