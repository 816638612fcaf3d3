// The engine's latency histogram (microsecond buckets) as a Prometheus histogram in seconds.
#include <doctest/doctest.h>

#include <chrono>
#include <string>

#include "northbound/metrics/latency_histogram.hpp"

namespace fieldbridge::northbound::metrics {
namespace {

using std::chrono::microseconds;

TEST_CASE("bounds become seconds, counts stay per bucket, the sum is in seconds") {
    engine::LatencyHistogram h;
    h.record(microseconds{400});      // <= 0.5 ms
    h.record(microseconds{500});      // <= 0.5 ms (bounds are inclusive)
    h.record(microseconds{2'500});    // <= 3 ms
    h.record(microseconds{2'000'000});  // above 1 s
    const HistogramValue v = to_histogram(h);
    REQUIRE(v.bounds.size() == engine::LatencyHistogram::bounds.size());
    REQUIRE(v.counts.size() == engine::LatencyHistogram::bucket_count);
    CHECK(v.bounds.front() == doctest::Approx(0.0005));
    CHECK(v.bounds.back() == doctest::Approx(1.0));
    CHECK(v.counts[0] == 2);
    CHECK(v.counts[3] == 1);
    CHECK(v.counts.back() == 1);
    CHECK(v.sum == doctest::Approx(2.0034));  // 0.4 + 0.5 + 2.5 + 2000 ms
}

TEST_CASE("rendered: cumulative buckets from 0.0005 to 1 s, +Inf equals _count equals the samples") {
    engine::LatencyHistogram h;
    for (int i = 0; i < 5; ++i) h.record(microseconds{2'500});
    h.record(microseconds{150'000});
    MetricSet set;
    set.add_histogram("fieldbridge_line_transaction_duration_seconds", "Latency", {{"line", "bus1"}},
                      to_histogram(h));
    const std::string text = set.render();
    const std::string prefix = "fieldbridge_line_transaction_duration_seconds";
    CHECK(text.find(prefix + "_bucket{line=\"bus1\",le=\"0.0005\"} 0\n") != std::string::npos);
    CHECK(text.find(prefix + "_bucket{line=\"bus1\",le=\"0.002\"} 0\n") != std::string::npos);
    CHECK(text.find(prefix + "_bucket{line=\"bus1\",le=\"0.003\"} 5\n") != std::string::npos);
    CHECK(text.find(prefix + "_bucket{line=\"bus1\",le=\"0.1\"} 5\n") != std::string::npos);
    CHECK(text.find(prefix + "_bucket{line=\"bus1\",le=\"0.2\"} 6\n") != std::string::npos);
    CHECK(text.find(prefix + "_bucket{line=\"bus1\",le=\"1\"} 6\n") != std::string::npos);
    CHECK(text.find(prefix + "_bucket{line=\"bus1\",le=\"+Inf\"} 6\n") != std::string::npos);
    CHECK(text.find(prefix + "_sum{line=\"bus1\"} 0.1625\n") != std::string::npos);
    CHECK(text.find(prefix + "_count{line=\"bus1\"} 6\n") != std::string::npos);
}

}  // namespace
}  // namespace fieldbridge::northbound::metrics
