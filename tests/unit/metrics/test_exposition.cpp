// The Prometheus text writer: families, escaping, histograms, number formatting,
// and the names it refuses.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/error.hpp"
#include "northbound/metrics/exposition.hpp"

namespace fieldbridge::northbound::metrics {
namespace {

TEST_CASE("families are written once, in order of their first sample, with HELP and TYPE") {
    MetricSet set;
    set.add_counter("fb_requests_total", "Requests sent", {{"line", "a"}}, 3);
    set.add_gauge("fb_up", "1 when up", {}, 1);
    set.add_counter("fb_requests_total", "Requests sent", {{"line", "b"}}, 40);
    CHECK(set.render() ==
          "# HELP fb_requests_total Requests sent\n"
          "# TYPE fb_requests_total counter\n"
          "fb_requests_total{line=\"a\"} 3\n"
          "fb_requests_total{line=\"b\"} 40\n"
          "# HELP fb_up 1 when up\n"
          "# TYPE fb_up gauge\n"
          "fb_up 1\n");
}

TEST_CASE("a table of counters shares its labels") {
    MetricSet set;
    set.add_counters({{"line", "a"}}, {{"fb_a_total", "A", 1}, {"fb_b_total", "B", 18446744073709551615U}});
    CHECK(set.render() ==
          "# HELP fb_a_total A\n"
          "# TYPE fb_a_total counter\n"
          "fb_a_total{line=\"a\"} 1\n"
          "# HELP fb_b_total B\n"
          "# TYPE fb_b_total counter\n"
          "fb_b_total{line=\"a\"} 18446744073709551616\n");  // a double: exact up to 2^53
}

TEST_CASE("label values escape backslash, double quote and newline; HELP escapes backslash and newline") {
    CHECK(escape_label_value(R"(a\b"c)" "\n" "d") == R"(a\\b\"c\nd)");
    CHECK(escape_label_value("plain ü") == "plain ü");
    MetricSet set;
    set.add_gauge("fb_g", "line one\nback\\slash \"quoted\"", {{"device", "x\"y"}, {"line", "l\\1"}}, 2.5);
    CHECK(set.render() ==
          "# HELP fb_g line one\\nback\\\\slash \"quoted\"\n"
          "# TYPE fb_g gauge\n"
          "fb_g{device=\"x\\\"y\",line=\"l\\\\1\"} 2.5\n");
}

TEST_CASE("a histogram is written cumulative with +Inf, _sum and _count") {
    MetricSet set;
    set.add_histogram("fb_latency_seconds", "Latency", {{"line", "a"}},
                      HistogramValue{{0.0005, 0.001, 0.25}, {1, 0, 2, 4}, 7.125});
    CHECK(set.render() ==
          "# HELP fb_latency_seconds Latency\n"
          "# TYPE fb_latency_seconds histogram\n"
          "fb_latency_seconds_bucket{line=\"a\",le=\"0.0005\"} 1\n"
          "fb_latency_seconds_bucket{line=\"a\",le=\"0.001\"} 1\n"
          "fb_latency_seconds_bucket{line=\"a\",le=\"0.25\"} 3\n"
          "fb_latency_seconds_bucket{line=\"a\",le=\"+Inf\"} 7\n"
          "fb_latency_seconds_sum{line=\"a\"} 7.125\n"
          "fb_latency_seconds_count{line=\"a\"} 7\n");
}

TEST_CASE("an empty histogram still has every bucket at zero") {
    MetricSet set;
    set.add_histogram("fb_wait_seconds", "Wait", {}, HistogramValue{{1.0}, {0, 0}, 0.0});
    CHECK(set.render() ==
          "# HELP fb_wait_seconds Wait\n"
          "# TYPE fb_wait_seconds histogram\n"
          "fb_wait_seconds_bucket{le=\"1\"} 0\n"
          "fb_wait_seconds_bucket{le=\"+Inf\"} 0\n"
          "fb_wait_seconds_sum 0\n"
          "fb_wait_seconds_count 0\n");
}

TEST_CASE("values: shortest decimal, no exponent for ordinary magnitudes, special values by name") {
    CHECK(format_value(0) == "0");
    CHECK(format_value(42) == "42");
    CHECK(format_value(0.0005) == "0.0005");
    CHECK(format_value(0.1) == "0.1");
    CHECK(format_value(12345678901234.0) == "12345678901234");
    CHECK(format_value(-1.5) == "-1.5");
    CHECK(format_value(std::numeric_limits<double>::infinity()) == "+Inf");
    CHECK(format_value(-std::numeric_limits<double>::infinity()) == "-Inf");
    CHECK(format_value(std::nan("")) == "NaN");
}

TEST_CASE("names Prometheus would refuse are programming errors") {
    MetricSet set;
    CHECK_THROWS_AS(set.add_gauge("1bad", "h", {}, 1), fieldbridge::core::InvalidArgument);
    CHECK_THROWS_AS(set.add_gauge("fb-bad", "h", {}, 1), fieldbridge::core::InvalidArgument);
    CHECK_THROWS_AS(set.add_gauge("fb_g", "h", {{"bad-label", "v"}}, 1), fieldbridge::core::InvalidArgument);
    CHECK_THROWS_AS(set.add_gauge("fb_g", "h", {{"__reserved", "v"}}, 1), fieldbridge::core::InvalidArgument);
    CHECK_THROWS_AS(set.add_counter("fb_requests", "h", {}, 1), fieldbridge::core::InvalidArgument);  // no _total
    CHECK_THROWS_AS(set.add_histogram("fb_h", "h", {{"le", "1"}}, HistogramValue{{1.0}, {0, 0}, 0}),
                    fieldbridge::core::InvalidArgument);
    CHECK_THROWS_AS(set.add_histogram("fb_h", "h", {}, HistogramValue{{1.0}, {0}, 0}), fieldbridge::core::InvalidArgument);
    CHECK_THROWS_AS(set.add_histogram("fb_h", "h", {}, HistogramValue{{2.0, 1.0}, {0, 0, 0}, 0}),
                    fieldbridge::core::InvalidArgument);
    set.add_gauge("fb_mixed_total", "h", {}, 1);
    CHECK_THROWS_AS(set.add_counter("fb_mixed_total", "h", {}, 1), fieldbridge::core::InvalidArgument);  // one type per name
}

}  // namespace
}  // namespace fieldbridge::northbound::metrics
