#include "northbound/mqtt/bridge_settings.hpp"

namespace fieldbridge::northbound::mqtt {

BridgeSettings bridge_settings(const config::MqttConfig& config) {
    BridgeSettings s;
    s.prefix = config.prefix;
    s.qos = config.qos;
    s.throttle.min_interval = config.min_interval;
    s.throttle.heartbeat = config.heartbeat;
    for (const auto& [field, band] : config.deadband) s.throttle.deadband.emplace(field, band);
    s.diag_period = config.diag_period;
    s.reconnect_initial = config.reconnect_backoff.initial;
    s.reconnect_max = config.reconnect_backoff.max;
    s.outbox_max_bytes = config.outbox_max_bytes;
    s.outbox_capacity = config.outbox_max_messages;
    s.max_command_bytes = config.max_command_bytes;
    s.max_command_id_length = config.max_command_id_length;
    return s;
}

}  // namespace fieldbridge::northbound::mqtt
