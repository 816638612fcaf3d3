#include "northbound/sparkplug_node/node_metrics.hpp"

#include <algorithm>
#include <utility>

namespace fieldbridge::northbound::sparkplug_node {
namespace {

using sparkplug::DataType;
using sparkplug::Metric;

Metric metric(std::string name, DataType type, sparkplug::Value value, std::uint64_t now_ms) {
    Metric m;
    m.name = std::move(name);
    m.datatype = type;
    m.value = std::move(value);
    m.timestamp = now_ms;
    return m;
}

}  // namespace

std::vector<Metric> node_metrics(const NodeSnapshot& s, std::uint64_t now_ms) {
    std::vector<Metric> out;
    out.push_back(metric("Properties/Software Version", DataType::string, s.version, now_ms));
    out.push_back(metric("Properties/JSON Bridge", DataType::string, s.json_bridge, now_ms));
    out.push_back(metric("Properties/Commands Accepted", DataType::uint64, s.commands_accepted, now_ms));
    out.push_back(metric("Properties/Commands Refused", DataType::uint64, s.commands_refused, now_ms));
    for (const LineSnapshot& line : s.lines) {
        const std::string folder = "Lines/" + line.name + "/";
        out.push_back(metric(folder + "Up", DataType::boolean, line.up, now_ms));
        out.push_back(metric(folder + "Requests", DataType::uint64, line.requests, now_ms));
        out.push_back(metric(folder + "Timeouts", DataType::uint64, line.timeouts, now_ms));
        out.push_back(metric(folder + "Transactions Per Second", DataType::float64, line.transactions_per_second, now_ms));
        out.push_back(metric(folder + "Utilisation Pct", DataType::float64, line.utilisation_pct, now_ms));
    }
    for (const UpstreamSnapshot& upstream : s.upstreams) {
        out.push_back(metric("Upstreams/" + upstream.name + "/Link", DataType::string, upstream.link, now_ms));
    }
    return out;
}

std::vector<Metric> changed_node_metrics(const std::vector<Metric>& before, const std::vector<Metric>& now) {
    std::vector<Metric> out;
    for (const Metric& m : now) {
        const auto old = std::find_if(before.begin(), before.end(), [&](const Metric& b) { return b.name == m.name; });
        if (old == before.end() || old->value != m.value) out.push_back(m);
    }
    return out;
}

}  // namespace fieldbridge::northbound::sparkplug_node
