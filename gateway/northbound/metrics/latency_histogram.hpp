#pragma once
/// @file latency_histogram.hpp
/// An engine latency histogram (fixed buckets in microseconds) as a Prometheus
/// histogram in seconds.
#include "engine/line_stats.hpp"
#include "northbound/metrics/exposition.hpp"

namespace fieldbridge::northbound::metrics {

/// Bounds LatencyHistogram::bounds in seconds, the same bucket counts, the sum in seconds.
[[nodiscard]] HistogramValue to_histogram(const engine::LatencyHistogram& histogram);

}  // namespace fieldbridge::northbound::metrics
