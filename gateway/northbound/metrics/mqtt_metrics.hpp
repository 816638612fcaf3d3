#pragma once
/// @file mqtt_metrics.hpp
/// The MQTT bridge's connection state and publication counters as Prometheus
/// metrics (docs/service.md, "Metrics"). Loop thread only.
#include "northbound/metrics/exposition.hpp"
#include "northbound/mqtt/mqtt_bridge.hpp"

namespace fieldbridge::northbound::metrics {

/// Nothing when @p bridge is nullptr (MQTT off).
void collect_mqtt(MetricSet& out, const mqtt::Bridge* bridge);

}  // namespace fieldbridge::northbound::metrics
