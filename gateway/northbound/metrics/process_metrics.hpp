#pragma once
/// @file process_metrics.hpp
/// Samples about the gateway process itself: configuration reloads.
#include <cstdint>

#include "northbound/metrics/exposition.hpp"

namespace fieldbridge::northbound::metrics {

/// `fieldbridge_reloads_total{result="ok|rejected"}`.
void collect_reloads(MetricSet& out, std::uint64_t ok, std::uint64_t rejected);

}  // namespace fieldbridge::northbound::metrics
