#include "northbound/metrics/mqtt_metrics.hpp"

namespace fieldbridge::northbound::metrics {

void collect_mqtt(MetricSet& out, const mqtt::Bridge* bridge) {
    if (bridge == nullptr) return;
    out.add_gauge("fieldbridge_mqtt_connected", "1 while the MQTT client is connected to the broker", {},
                  bridge->connected() ? 1 : 0);
    const mqtt::BridgeStats s = bridge->stats();
    out.add_counters(
        {}, {{"fieldbridge_mqtt_connects_total", "Successful connections to the broker", s.connects},
             {"fieldbridge_mqtt_connect_failures_total", "Failed connection attempts", s.connect_failures},
             {"fieldbridge_mqtt_connection_losses_total", "Connections lost", s.connection_losses},
             {"fieldbridge_mqtt_published_total", "Messages acknowledged (QoS 1/2) or handed over (QoS 0)",
              s.published},
             {"fieldbridge_mqtt_publish_failures_total", "Publications refused by the client or failed",
              s.publish_failures},
             {"fieldbridge_mqtt_dropped_total", "Publications dropped because the outbox was full", s.dropped},
             {"fieldbridge_mqtt_resent_total", "Events and command results sent again after a lost connection",
              s.resent},
             {"fieldbridge_mqtt_state_messages_total", "Device state messages published", s.state_messages},
             {"fieldbridge_mqtt_alarm_events_total", "Alarm raise and clear events published", s.alarm_events},
             {"fieldbridge_mqtt_commands_total", "Commands received", s.commands},
             {"fieldbridge_mqtt_commands_failed_total", "Commands that failed", s.commands_failed}});
    out.add_gauge("fieldbridge_mqtt_in_flight", "Publications sent and not yet acknowledged", {},
                  static_cast<double>(s.in_flight));
    out.add_gauge("fieldbridge_mqtt_queued", "Publications waiting in the outbox", {}, static_cast<double>(s.queued));
}

}  // namespace fieldbridge::northbound::metrics
