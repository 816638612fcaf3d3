#include "northbound/metrics/exposition.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "core/error.hpp"

namespace fieldbridge::northbound::metrics {

namespace {

[[nodiscard]] bool is_name_start(char c, bool colon_allowed) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' || (colon_allowed && c == ':');
}

/// Metric names: [a-zA-Z_:][a-zA-Z0-9_:]*; label names the same without `:`.
[[nodiscard]] bool is_valid_name(std::string_view name, bool colon_allowed) {
    if (name.empty() || !is_name_start(name.front(), colon_allowed)) return false;
    for (const char c : name) {
        if (!is_name_start(c, colon_allowed) && !(c >= '0' && c <= '9')) return false;
    }
    return true;
}

[[nodiscard]] const char* type_name(MetricType type) {
    switch (type) {
        case MetricType::counter: return "counter";
        case MetricType::gauge: return "gauge";
        case MetricType::histogram: return "histogram";
    }
    return "untyped";
}

/// HELP text: `\` → `\\`, newline → `\n` (the format escapes no quotes there).
[[nodiscard]] std::string escape_help(std::string_view help) {
    std::string out;
    out.reserve(help.size());
    for (const char c : help) {
        if (c == '\\') {
            out += "\\\\";
        } else if (c == '\n') {
            out += "\\n";
        } else {
            out += c;
        }
    }
    return out;
}

/// `{a="x",b="y"}` with @p extra (the histogram's `le`) last; nothing for no labels.
void write_labels(std::string& out, const Labels& labels, const Label* extra) {
    if (labels.empty() && extra == nullptr) return;
    out += '{';
    bool first = true;
    const auto write_one = [&out, &first](const Label& label) {
        if (!first) out += ',';
        first = false;
        out += label.name;
        out += "=\"";
        out += escape_label_value(label.value);
        out += '"';
    };
    for (const Label& label : labels) write_one(label);
    if (extra != nullptr) write_one(*extra);
    out += '}';
}

void write_sample(std::string& out, std::string_view name, std::string_view suffix, const Labels& labels,
                  const Label* extra, std::string_view value) {
    out += name;
    out += suffix;
    write_labels(out, labels, extra);
    out += ' ';
    out += value;
    out += '\n';
}

void write_histogram(std::string& out, std::string_view name, const Labels& labels, const HistogramValue& h) {
    std::uint64_t cumulative = 0;
    for (std::size_t i = 0; i < h.counts.size(); ++i) {
        cumulative += h.counts[i];
        const Label le{"le", i < h.bounds.size() ? format_value(h.bounds[i]) : "+Inf"};
        write_sample(out, name, "_bucket", labels, &le, std::to_string(cumulative));
    }
    write_sample(out, name, "_sum", labels, nullptr, format_value(h.sum));
    write_sample(out, name, "_count", labels, nullptr, std::to_string(cumulative));
}

void check_histogram(std::string_view name, const HistogramValue& value) {
    bool ascending = true;
    for (std::size_t i = 1; i < value.bounds.size(); ++i) ascending = ascending && value.bounds[i - 1] < value.bounds[i];
    if (value.counts.size() != value.bounds.size() + 1 || !ascending) {
        throw core::InvalidArgument("metric " + std::string(name) +
                                    ": histogram needs ascending bounds and one count more than bounds");
    }
}

}  // namespace

std::string escape_label_value(std::string_view value) {
    std::string out;
    out.reserve(value.size());
    for (const char c : value) {
        switch (c) {
            case '\\': out += "\\\\"; break;
            case '"': out += "\\\""; break;
            case '\n': out += "\\n"; break;
            default: out += c; break;
        }
    }
    return out;
}

std::string format_value(double value) {
    if (std::isnan(value)) return "NaN";
    if (std::isinf(value)) return value > 0 ? "+Inf" : "-Inf";
    // Fixed notation, shortest round trip: 0.0005 stays 0.0005 (as client_golang
    // writes bucket bounds), 42.0 is 42. 400 characters hold any finite double.
    std::array<char, 400> buffer{};
    const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value, std::chars_format::fixed);
    return std::string(buffer.data(), result.ptr);
}

MetricSet::Family& MetricSet::family(std::string_view name, std::string_view help, MetricType type,
                                     const Labels& labels) {
    if (!is_valid_name(name, true)) throw core::InvalidArgument("invalid metric name '" + std::string(name) + "'");
    for (const Label& label : labels) {
        if (!is_valid_name(label.name, false) || label.name.starts_with("__") ||
            (type == MetricType::histogram && label.name == "le")) {
            throw core::InvalidArgument("metric " + std::string(name) + ": invalid label name '" + label.name + "'");
        }
    }
    const auto found = index_.find(name);
    if (found != index_.end()) {
        Family& existing = families_[found->second];
        if (existing.type != type) {
            throw core::InvalidArgument("metric " + std::string(name) + " added as " + type_name(type) +
                                        " but it is a " + type_name(existing.type));
        }
        return existing;
    }
    index_.emplace(std::string(name), families_.size());
    families_.push_back(Family{std::string(name), std::string(help), type, {}});
    return families_.back();
}

void MetricSet::add_counter(std::string_view name, std::string_view help, Labels labels, double value) {
    if (!name.ends_with("_total")) {
        throw core::InvalidArgument("counter " + std::string(name) + " must end in _total");
    }
    family(name, help, MetricType::counter, labels).samples.push_back(Sample{std::move(labels), value, {}});
}

void MetricSet::add_counters(const Labels& labels, std::initializer_list<CounterRow> rows) {
    for (const CounterRow& row : rows) add_counter(row.name, row.help, labels, static_cast<double>(row.value));
}

void MetricSet::add_gauge(std::string_view name, std::string_view help, Labels labels, double value) {
    family(name, help, MetricType::gauge, labels).samples.push_back(Sample{std::move(labels), value, {}});
}

void MetricSet::add_histogram(std::string_view name, std::string_view help, Labels labels, HistogramValue value) {
    check_histogram(name, value);
    family(name, help, MetricType::histogram, labels).samples.push_back(Sample{std::move(labels), 0.0, std::move(value)});
}

std::string MetricSet::render() const {
    std::string out;
    for (const Family& f : families_) {
        out += "# HELP ";
        out += f.name;
        out += ' ';
        out += escape_help(f.help);
        out += "\n# TYPE ";
        out += f.name;
        out += ' ';
        out += type_name(f.type);
        out += '\n';
        for (const Sample& sample : f.samples) {
            if (f.type == MetricType::histogram) {
                write_histogram(out, f.name, sample.labels, sample.histogram);
            } else {
                write_sample(out, f.name, "", sample.labels, nullptr, format_value(sample.value));
            }
        }
    }
    return out;
}

}  // namespace fieldbridge::northbound::metrics
