#pragma once
/// @file node_metrics.hpp
/// The edge node's own metrics (docs/sparkplug.md, "Node metrics"): the software
/// version, the JSON bridge's state, the DCMD counters, each line's state and load,
/// each upstream's link. Built from a snapshot the daemon takes; pure.
#include <cstdint>
#include <string>
#include <vector>

#include "northbound/sparkplug/payload.hpp"

namespace fieldbridge::northbound::sparkplug_node {

struct LineSnapshot {
    std::string name;
    bool up = false;
    std::uint64_t requests = 0;
    std::uint64_t timeouts = 0;
    double transactions_per_second = 0;  ///< since the previous snapshot
    double utilisation_pct = 0;          ///< since the previous snapshot
};

struct UpstreamSnapshot {
    std::string name;
    std::string link;  ///< the link state's name
};

struct NodeSnapshot {
    std::string version;
    std::string json_bridge;  ///< "connected", "connecting" or "off"
    std::uint64_t commands_accepted = 0;
    std::uint64_t commands_refused = 0;
    std::vector<LineSnapshot> lines;
    std::vector<UpstreamSnapshot> upstreams;
};

/// The node metrics of @p snapshot, named (`Properties/…`, `Lines/<line>/…`,
/// `Upstreams/<name>/…`), typed and valued, stamped @p now_ms; no aliases.
[[nodiscard]] std::vector<sparkplug::Metric> node_metrics(const NodeSnapshot& snapshot, std::uint64_t now_ms);

/// The metrics of @p now whose value differs from the same-named one of @p before
/// (all of them when a name is new).
[[nodiscard]] std::vector<sparkplug::Metric> changed_node_metrics(const std::vector<sparkplug::Metric>& before,
                                                                  const std::vector<sparkplug::Metric>& now);

}  // namespace fieldbridge::northbound::sparkplug_node
