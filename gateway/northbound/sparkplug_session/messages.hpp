#pragma once
/// @file messages.hpp
/// The payloads of the edge node's messages, built from the metrics the catalogue
/// gives (Sparkplug 3.0, "Payloads"). No seq here: the session numbers what it
/// publishes. Pure.
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "northbound/sparkplug/payload.hpp"

namespace fieldbridge::northbound::sparkplug_session {

/// The two metrics every NBIRTH carries first, never aliased.
inline constexpr std::string_view bdseq_metric_name = "bdSeq";
inline constexpr std::string_view rebirth_metric_name = "Node Control/Rebirth";

/// The `bdSeq` metric: Int64 (tck-id-payloads-ndeath-bdseq, tck-id-topics-nbirth-bdseq-included).
[[nodiscard]] sparkplug::Metric bdseq_metric(std::uint8_t bd_seq, std::uint64_t now_ms);

/// NDEATH: the bdSeq metric and nothing else, no seq (tck-id-topics-ndeath-payload,
/// tck-id-topics-ndeath-seq). The will carries no timestamp (it is made at CONNECT
/// time, long before it is delivered); an NDEATH the node publishes itself does.
[[nodiscard]] sparkplug::Payload ndeath_payload(std::uint8_t bd_seq, std::optional<std::uint64_t> now_ms);

/// NBIRTH without seq: bdSeq, `Node Control/Rebirth` = false (Boolean), then every
/// node metric (tck-id-topics-nbirth-bdseq-included, tck-id-topics-nbirth-rebirth-metric,
/// tck-id-topics-nbirth-metric-reqs, tck-id-topics-nbirth-timestamp).
[[nodiscard]] sparkplug::Payload nbirth_payload(std::uint8_t bd_seq, const std::vector<sparkplug::Metric>& node_metrics,
                                                bool aliases, std::uint64_t now_ms);

/// DBIRTH without seq: every metric of the device with its name, and its alias when
/// @p aliases (tck-id-topics-dbirth-metric-reqs, tck-id-topics-dbirth-timestamp).
[[nodiscard]] sparkplug::Payload dbirth_payload(const std::vector<sparkplug::Metric>& metrics, bool aliases,
                                                std::uint64_t now_ms);

/// NDATA / DDATA without seq: the changed metrics, by alias only when @p aliases and
/// the metric has one (tck-id-payloads-alias-data-cmd-requirement), each marked
/// historical when @p historical (buffered data published after the births).
[[nodiscard]] sparkplug::Payload data_payload(std::vector<sparkplug::Metric> metrics, bool aliases, bool historical,
                                              std::uint64_t now_ms);

/// DDEATH without seq: a timestamp, no metrics.
[[nodiscard]] sparkplug::Payload ddeath_payload(std::uint64_t now_ms);

/// True when @p a and @p b define the same metrics: names, aliases, datatypes and
/// properties, in order; values and timestamps are not compared.
[[nodiscard]] bool same_definitions(const std::vector<sparkplug::Metric>& a, const std::vector<sparkplug::Metric>& b);

}  // namespace fieldbridge::northbound::sparkplug_session
