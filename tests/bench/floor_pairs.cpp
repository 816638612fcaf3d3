#include "floor_pairs.hpp"

#include <cstdio>
#include <utility>

#include "percentile.hpp"

namespace fieldbridge::bench {
namespace {

template <typename Figure>
double median_over(const std::vector<FloorPair>& pairs, Figure figure) {
    std::vector<double> values;
    values.reserve(pairs.size());
    for (const FloorPair& pair : pairs) values.push_back(figure(pair));
    return median_of(std::move(values));
}

}  // namespace

double FloorPair::rate_ratio() const noexcept { return floor.tps > 0.0 ? gateway.tps / floor.tps : 0.0; }

double FloorPair::cpu_ratio() const noexcept { return floor.cpu_us > 0.0 ? gateway.cpu_us / floor.cpu_us : 0.0; }

double closed_loop_ceiling(double floor_tps, double round_trip_us, double silence_us) noexcept {
    if (floor_tps <= 0.0) return 0.0;
    const double period_us = 1e6 / floor_tps;
    const double idle_us = round_trip_us > silence_us ? round_trip_us - silence_us : 0.0;
    return period_us / (period_us + idle_us);
}

void FloorPairs::add(const char* bench, const char* gateway, const FloorPair& pair) {
    pairs_.push_back(pair);
    std::printf("%s pair %zu: floor %.1f tx/s, %.1f us/tx; %s %.1f tx/s, %.1f us/tx; ratios rate %.3f, CPU %.2fx\n",
                bench, pairs_.size(), pair.floor.tps, pair.floor.cpu_us, gateway, pair.gateway.tps,
                pair.gateway.cpu_us, pair.rate_ratio(), pair.cpu_ratio());
}

double FloorPairs::median_rate_ratio() const {
    return median_over(pairs_, [](const FloorPair& pair) { return pair.rate_ratio(); });
}

double FloorPairs::median_cpu_ratio() const {
    return median_over(pairs_, [](const FloorPair& pair) { return pair.cpu_ratio(); });
}

WindowFigures FloorPairs::median_floor() const {
    return {median_over(pairs_, [](const FloorPair& pair) { return pair.floor.tps; }),
            median_over(pairs_, [](const FloorPair& pair) { return pair.floor.cpu_us; })};
}

WindowFigures FloorPairs::median_gateway() const {
    return {median_over(pairs_, [](const FloorPair& pair) { return pair.gateway.tps; }),
            median_over(pairs_, [](const FloorPair& pair) { return pair.gateway.cpu_us; })};
}

}  // namespace fieldbridge::bench
