#pragma once
/// @file percentile.hpp
/// The benchmarks' one percentile: nearest rank over an already sorted sample, and
/// the median of an unsorted one.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace fieldbridge::bench {

/// The value at fraction @p p (0..1) of @p sorted (ascending), nearest rank; 0 when empty.
[[nodiscard]] inline double percentile_of_sorted(const std::vector<double>& sorted, double p) {
    if (sorted.empty()) return 0.0;
    const auto rank = static_cast<std::size_t>(p * static_cast<double>(sorted.size() - 1) + 0.5);
    return sorted[std::min(rank, sorted.size() - 1)];
}

/// The usual three figures of a latency sample.
struct Spread {
    std::size_t count = 0;
    double p50 = 0.0;
    double p99 = 0.0;
    double max = 0.0;
};

/// p50, p99 (nearest rank) and the maximum of @p values (any order); zeros when empty.
[[nodiscard]] inline Spread spread_of(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    return {values.size(), percentile_of_sorted(values, 0.50), percentile_of_sorted(values, 0.99),
            values.empty() ? 0.0 : values.back()};
}

/// The median of @p values (any order), nearest rank; 0 when empty.
[[nodiscard]] inline double median_of(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    return percentile_of_sorted(values, 0.5);
}

}  // namespace fieldbridge::bench
