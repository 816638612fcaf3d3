#include "northbound/metrics/latency_histogram.hpp"

#include <chrono>

namespace fieldbridge::northbound::metrics {

HistogramValue to_histogram(const engine::LatencyHistogram& histogram) {
    HistogramValue out;
    out.bounds.reserve(engine::LatencyHistogram::bounds.size());
    for (const auto bound : engine::LatencyHistogram::bounds) {
        out.bounds.push_back(std::chrono::duration<double>(bound).count());
    }
    out.counts.reserve(engine::LatencyHistogram::bucket_count);
    for (std::size_t i = 0; i < engine::LatencyHistogram::bucket_count; ++i) out.counts.push_back(histogram.bucket(i));
    out.sum = std::chrono::duration<double>(histogram.sum()).count();
    return out;
}

}  // namespace fieldbridge::northbound::metrics
