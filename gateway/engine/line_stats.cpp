#include "engine/line_stats.hpp"

#include <algorithm>
#include <cmath>

namespace fieldbridge::engine {

void LatencyHistogram::record(Duration value) noexcept {
    const auto it = std::lower_bound(bounds.begin(), bounds.end(), value);
    ++buckets_[static_cast<std::size_t>(it - bounds.begin())];
    ++count_;
    sum_ += value;
    max_ = std::max(max_, value);
}

Duration LatencyHistogram::quantile_upper_bound(double fraction) const noexcept {
    if (count_ == 0) return Duration{};
    const double clamped = std::clamp(fraction, 0.0, 1.0);
    const auto rank = std::max<std::uint64_t>(
        1, static_cast<std::uint64_t>(std::ceil(clamped * static_cast<double>(count_))));
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i < bounds.size(); ++i) {
        seen += buckets_[i];
        if (seen >= rank) return std::min<Duration>(bounds[i], max_);
    }
    return max_;
}

}  // namespace fieldbridge::engine
