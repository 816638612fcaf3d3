#include "northbound/metrics/modbus_tcp_metrics.hpp"

#include <fmt/format.h>
#include <initializer_list>
#include <utility>

namespace fieldbridge::northbound::metrics {

namespace {

[[nodiscard]] double tcp_count(std::uint64_t count) {
    return static_cast<double>(count);
}

void add_by_reason(MetricSet& out, const char* name, const char* help,
                   std::initializer_list<std::pair<const char*, std::uint64_t>> reasons) {
    for (const auto& [reason, count] : reasons) out.add_counter(name, help, {{"reason", reason}}, tcp_count(count));
}

void collect_upstream(MetricSet& out, const upstream::UpstreamTarget& target) {
    const Labels name{{"upstream", target.config().name}};
    const upstream::LinkState state = target.link_state();
    out.add_gauge("fieldbridge_upstream_up", "1 while the TCP connection to the upstream is established", name,
                  state == upstream::LinkState::up ? 1 : 0);
    for (const auto candidate : {upstream::LinkState::stopped, upstream::LinkState::connecting,
                                 upstream::LinkState::up, upstream::LinkState::backoff}) {
        Labels labels = name;
        labels.push_back({"state", upstream::to_string(candidate)});
        out.add_gauge("fieldbridge_upstream_link_state", "1 for the link's current state, 0 for the others",
                      std::move(labels), state == candidate ? 1 : 0);
    }
    const upstream::UpstreamStats s = target.stats();
    out.add_counters(
        name,
        {{"fieldbridge_upstream_requests_total", "Client requests handled for the upstream's units", s.requests},
         {"fieldbridge_upstream_forwarded_total", "Frames sent to the upstream (polls included)", s.forwarded},
         {"fieldbridge_upstream_replies_total", "Replies matched to a request", s.replies},
         {"fieldbridge_upstream_late_replies_total", "Replies that came after their request was answered",
          s.late_replies},
         {"fieldbridge_upstream_malformed_replies_total", "Replies that did not fit their request",
          s.malformed_replies},
         {"fieldbridge_upstream_timeouts_total", "Requests the upstream did not answer in time", s.timeouts},
         {"fieldbridge_upstream_expired_total", "Requests whose deadline passed before they were sent", s.expired},
         {"fieldbridge_upstream_queue_full_total", "Requests refused because the queue was full", s.queue_full},
         {"fieldbridge_upstream_path_down_total", "Requests answered 0x0A because the link was down", s.path_down},
         {"fieldbridge_upstream_connects_total", "TCP connections established to the upstream", s.connects},
         {"fieldbridge_upstream_poll_cycles_total", "Completed polling cycles", s.poll_cycles}});
}

}  // namespace

void collect_modbus_tcp(MetricSet& out, const modbus_tcp::ServerStats& stats) {
    out.add_gauge("fieldbridge_modbus_tcp_clients", "Modbus TCP client connections open now", {},
                  tcp_count(stats.connections_open));
    out.add_counters({}, {{"fieldbridge_modbus_tcp_connections_accepted_total", "Client connections accepted",
                           stats.connections_accepted}});
    add_by_reason(out, "fieldbridge_modbus_tcp_connections_refused_total", "Client connections refused, by reason",
                  {{"max_connections", stats.refused_max_connections},
                   {"not_allowed", stats.refused_not_allowed},
                   {"per_client", stats.refused_per_client}});
    add_by_reason(out, "fieldbridge_modbus_tcp_connections_closed_total",
                  "Client connections closed, by reason (peer: the client closed it)",
                  {{"peer", stats.closed_by_peer},
                   {"malformed", stats.closed_malformed},
                   {"frame_timeout", stats.closed_frame_timeout},
                   {"output_overflow", stats.closed_output_overflow},
                   {"idle", stats.closed_idle},
                   {"io_error", stats.closed_io_error}});
    out.add_counters(
        {}, {{"fieldbridge_modbus_tcp_requests_total", "Complete MBAP requests received", stats.requests},
             {"fieldbridge_modbus_tcp_responses_total", "Responses sent (normal and exception)", stats.responses},
             {"fieldbridge_modbus_tcp_denied_total", "Requests refused by an access rule", stats.denied},
             {"fieldbridge_modbus_tcp_unknown_unit_total", "Requests to a unit ID without a route", stats.unknown_unit},
             {"fieldbridge_modbus_tcp_target_failures_total",
              "Requests whose target failed or answered an unusable PDU (answered 0x04)", stats.target_failures},
             {"fieldbridge_modbus_tcp_late_responses_total", "Answers dropped because their connection had closed",
              stats.late_responses}});
    for (std::size_t code = 0; code < stats.exceptions_by_code.size(); ++code) {
        if (stats.exceptions_by_code[code] == 0) continue;
        out.add_counter("fieldbridge_modbus_tcp_exceptions_total", "Exception responses sent, by exception code",
                        {{"code", fmt::format("0x{:02X}", code)}}, tcp_count(stats.exceptions_by_code[code]));
    }
}

void collect_upstreams(MetricSet& out, const std::vector<std::unique_ptr<upstream::UpstreamTarget>>& upstreams) {
    for (const auto& target : upstreams) {
        if (target) collect_upstream(out, *target);
    }
}

}  // namespace fieldbridge::northbound::metrics
