#pragma once
/// @file modbus_tcp_metrics.hpp
/// The Modbus TCP server's counters and the upstream (R6 pass-through) links as
/// Prometheus metrics (docs/service.md, "Metrics"). Loop thread only.
#include <memory>
#include <vector>

#include "northbound/metrics/exposition.hpp"
#include "northbound/modbus_tcp/server_stats.hpp"
#include "northbound/upstream/upstream_target.hpp"

namespace fieldbridge::northbound::metrics {

/// Exception responses are labelled by `code` as the Modbus spec writes them
/// (`0x0B`); codes never sent are left out.
void collect_modbus_tcp(MetricSet& out, const modbus_tcp::ServerStats& stats);

/// Per upstream (`upstream` label): link state and request counters.
void collect_upstreams(MetricSet& out, const std::vector<std::unique_ptr<upstream::UpstreamTarget>>& upstreams);

}  // namespace fieldbridge::northbound::metrics
