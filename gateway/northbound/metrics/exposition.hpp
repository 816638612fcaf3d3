#pragma once
/// @file exposition.hpp
/// The Prometheus text exposition format 0.0.4
/// (https://prometheus.io/docs/instrumenting/exposition_formats/): a scrape's
/// samples are gathered into a MetricSet, grouped by family (one `# HELP` and one
/// `# TYPE` per metric name, however many label sets), then rendered. Pure: no I/O,
/// no clock.
#include <cstdint>
#include <initializer_list>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace fieldbridge::northbound::metrics {

/// `Content-Type` of what MetricSet::render() returns.
inline constexpr std::string_view content_type = "text/plain; version=0.0.4; charset=utf-8";

enum class MetricType : std::uint8_t { counter, gauge, histogram };

struct Label {
    std::string name;   ///< [a-zA-Z_][a-zA-Z0-9_]*, not `le`
    std::string value;  ///< any UTF-8; escaped by the writer
};
using Labels = std::vector<Label>;

/// A histogram's samples by bucket. `counts[i]` holds the samples of bucket i
/// alone (at most `bounds[i]`, above the bound before it); `counts.back()` those above
/// the last bound, so `counts.size() == bounds.size() + 1`. The writer makes them
/// cumulative (`_bucket{le=...}`, `le="+Inf"` last) and writes `_count` as their total.
struct HistogramValue {
    std::vector<double> bounds;         ///< upper bounds, strictly ascending, base units
    std::vector<std::uint64_t> counts;  ///< bounds.size() + 1 entries
    double sum = 0.0;                   ///< of every sample, base units
};

/// One counter of a table given to MetricSet::add_counters().
struct CounterRow {
    std::string_view name;
    std::string_view help;
    std::uint64_t value = 0;
};

class MetricSet {
public:
    /// A counter sample; @p name ends in `_total`. Each add_*() throws
    /// core::InvalidArgument for a name or label name Prometheus does not accept, a
    /// name already used with another type, or a histogram whose counts do not fit
    /// its bounds: a programming error, caught by the unit tests.
    void add_counter(std::string_view name, std::string_view help, Labels labels, double value);
    /// Counters that share @p labels: one sample of each row.
    void add_counters(const Labels& labels, std::initializer_list<CounterRow> rows);
    void add_gauge(std::string_view name, std::string_view help, Labels labels, double value);
    /// Writes `<name>_bucket`, `<name>_sum` and `<name>_count`.
    void add_histogram(std::string_view name, std::string_view help, Labels labels, HistogramValue value);

    /// The exposition text, families in the order of their first sample.
    [[nodiscard]] std::string render() const;

private:
    struct Sample {
        Labels labels;
        double value = 0.0;
        HistogramValue histogram;
    };
    struct Family {
        std::string name;
        std::string help;
        MetricType type = MetricType::gauge;
        std::vector<Sample> samples;
    };
    [[nodiscard]] Family& family(std::string_view name, std::string_view help, MetricType type, const Labels& labels);

    std::vector<Family> families_;
    std::map<std::string, std::size_t, std::less<>> index_;
};

/// `\` → `\\`, `"` → `\"`, newline → `\n` (label values).
[[nodiscard]] std::string escape_label_value(std::string_view value);
/// A sample value: shortest decimal that reads back the same double, `+Inf`,
/// `-Inf`, `NaN`.
[[nodiscard]] std::string format_value(double value);

}  // namespace fieldbridge::northbound::metrics
