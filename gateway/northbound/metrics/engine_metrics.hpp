#pragma once
/// @file engine_metrics.hpp
/// The line engine's counters as Prometheus metrics (docs/service.md, "Metrics"):
/// per line (`line`) and per device (`line`, `device`, `unit`, and `class` for the
/// priority classes command / on_demand / poll). Reads the same counters as the MQTT
/// diag (app/engine_diag.hpp); loop thread only.
#include "engine/engine.hpp"
#include "northbound/metrics/exposition.hpp"

namespace fieldbridge::northbound::metrics {

void collect_engine(MetricSet& out, const engine::Engine& engine);

}  // namespace fieldbridge::northbound::metrics
