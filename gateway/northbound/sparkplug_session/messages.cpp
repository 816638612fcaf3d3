#include "northbound/sparkplug_session/messages.hpp"

#include <algorithm>
#include <string>
#include <utility>

namespace fieldbridge::northbound::sparkplug_session {

namespace {

using sparkplug::DataType;
using sparkplug::Metric;
using sparkplug::Payload;

/// A birth's metric: name, alias when aliases are on, and a timestamp (Ignition's
/// MQTT Engine fails on a metric without one).
Metric birth_metric(Metric metric, bool aliases, std::uint64_t now_ms) {
    if (!aliases) metric.alias.reset();
    if (!metric.timestamp) metric.timestamp = now_ms;
    metric.is_historical = false;
    return metric;
}

}  // namespace

Metric bdseq_metric(std::uint8_t bd_seq, std::uint64_t now_ms) {
    Metric metric;
    metric.name = std::string{bdseq_metric_name};
    metric.datatype = DataType::int64;
    metric.timestamp = now_ms;
    metric.value = std::uint64_t{bd_seq};
    return metric;
}

Payload ndeath_payload(std::uint8_t bd_seq, std::optional<std::uint64_t> now_ms) {
    Payload payload;
    payload.timestamp = now_ms;
    Metric metric = bdseq_metric(bd_seq, 0);
    metric.timestamp = now_ms;
    payload.metrics.push_back(std::move(metric));
    return payload;
}

Payload nbirth_payload(std::uint8_t bd_seq, const std::vector<Metric>& node_metrics, bool aliases,
                       std::uint64_t now_ms) {
    Payload payload;
    payload.timestamp = now_ms;
    payload.metrics.reserve(node_metrics.size() + 2);
    payload.metrics.push_back(bdseq_metric(bd_seq, now_ms));
    Metric rebirth;
    rebirth.name = std::string{rebirth_metric_name};
    rebirth.datatype = DataType::boolean;
    rebirth.timestamp = now_ms;
    rebirth.value = false;
    payload.metrics.push_back(std::move(rebirth));
    for (const Metric& metric : node_metrics) payload.metrics.push_back(birth_metric(metric, aliases, now_ms));
    return payload;
}

Payload dbirth_payload(const std::vector<Metric>& metrics, bool aliases, std::uint64_t now_ms) {
    Payload payload;
    payload.timestamp = now_ms;
    payload.metrics.reserve(metrics.size());
    for (const Metric& metric : metrics) payload.metrics.push_back(birth_metric(metric, aliases, now_ms));
    return payload;
}

Payload data_payload(std::vector<Metric> metrics, bool aliases, bool historical, std::uint64_t now_ms) {
    Payload payload;
    payload.timestamp = now_ms;
    for (Metric& metric : metrics) {
        if (aliases && metric.alias) {
            metric.name.reset();
        } else {
            metric.alias.reset();
        }
        // A data message carries values only: the birth defined the rest
        // (tck-id-payloads-metric-datatype-not-req).
        metric.datatype.reset();
        metric.properties.clear();
        if (!metric.timestamp) metric.timestamp = now_ms;
        metric.is_historical = historical;
    }
    payload.metrics = std::move(metrics);
    return payload;
}

Payload ddeath_payload(std::uint64_t now_ms) {
    Payload payload;
    payload.timestamp = now_ms;
    return payload;
}

bool same_definitions(const std::vector<Metric>& a, const std::vector<Metric>& b) {
    return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const Metric& x, const Metric& y) {
        return x.name == y.name && x.alias == y.alias && x.datatype == y.datatype && x.properties == y.properties;
    });
}

}  // namespace fieldbridge::northbound::sparkplug_session
