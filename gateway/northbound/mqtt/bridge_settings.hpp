#pragma once
/// @file bridge_settings.hpp
/// What the MQTT bridge (mqtt_bridge.hpp) runs by: topics, QoS, throttling, alarms,
/// back-off, bounds, with their defaults; and their values from the `mqtt` section.
#include <chrono>
#include <cstddef>
#include <string>

#include "config/config.hpp"
#include "engine/transaction.hpp"
#include "northbound/mqtt/alarm_tracker.hpp"
#include "northbound/mqtt/state_throttle.hpp"

namespace fieldbridge::northbound::mqtt {

struct BridgeSettings {
    std::string prefix = "fieldbridge/gateway";
    int qos = 1;
    ThrottleSettings throttle;
    AlarmSettings alarms;
    engine::Duration diag_period = std::chrono::seconds{10};
    engine::Duration reconnect_initial = std::chrono::seconds{1};
    engine::Duration reconnect_max = std::chrono::seconds{60};
    /// While a reconnect wait is longer than this, the broker's port is probed this
    /// often; a broker seen down that accepts connections again is connected to at once.
    engine::Duration probe_period = std::chrono::seconds{1};
    std::chrono::milliseconds probe_timeout{800};
    /// Every device is looked at this often even without a change notification
    /// (online transitions of a device that never answered, alarm holds).
    engine::Duration watch_period = std::chrono::seconds{1};
    std::size_t max_in_flight = 64;
    std::size_t outbox_capacity = 512;
    std::size_t outbox_max_bytes = 4 * 1024 * 1024;
    /// A larger command payload is refused (`too_large`) without being parsed.
    std::size_t max_command_bytes = 16 * 1024;
    /// A command's `id` (and `op`) are echoed and logged up to this many bytes.
    std::size_t max_command_id_length = 128;
    /// How long a clean stop waits for `offline` to be acknowledged, then for the
    /// disconnect.
    std::chrono::milliseconds stop_timeout{2000};
};

/// The settings of @p config (prefix, QoS, throttle, diag period, back-off).
[[nodiscard]] BridgeSettings bridge_settings(const config::MqttConfig& config);

}  // namespace fieldbridge::northbound::mqtt
