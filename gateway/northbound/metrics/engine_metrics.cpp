#include "northbound/metrics/engine_metrics.hpp"

#include <array>
#include <chrono>
#include <string>

#include "core/modbus_ids.hpp"
#include "northbound/metrics/latency_histogram.hpp"

namespace fieldbridge::northbound::metrics {

namespace {

/// By engine::Priority.
constexpr std::array<const char*, engine::priority_count> priority_labels{"command", "on_demand", "poll"};

[[nodiscard]] double as_seconds(engine::Duration d) {
    return std::chrono::duration<double>(d).count();
}

void collect_line(MetricSet& out, const engine::LineWorker& worker) {
    const Labels line{{"line", worker.config().name}};
    const engine::LineCounters& c = worker.master().counters();
    out.add_gauge("fieldbridge_line_up", "1 while the line's serial port is open", line, worker.line_up() ? 1 : 0);
    out.add_counters(
        line,
        {{"fieldbridge_line_requests_total", "Unicast requests written to the line (every attempt)", c.requests},
         {"fieldbridge_line_replies_total", "Valid replies (Modbus exception replies included)", c.replies},
         {"fieldbridge_line_timeouts_total", "Attempts that ended without a valid reply", c.timeouts},
         {"fieldbridge_line_crc_errors_total", "Frames dropped for a bad CRC", c.crc_errors},
         {"fieldbridge_line_wrong_address_total", "Runs of bytes dropped as coming from another slave",
          c.wrong_address},
         {"fieldbridge_line_bad_replies_total", "Well-framed replies that did not answer the request", c.bad_replies},
         {"fieldbridge_line_garbage_bytes_total", "Bytes dropped outside any recognised frame", c.garbage_bytes},
         {"fieldbridge_line_echo_mismatches_total", "Requests whose local echo differed from what was sent",
          c.echo_mismatch},
         {"fieldbridge_line_broadcasts_total", "Broadcasts written", c.broadcasts},
         {"fieldbridge_line_expired_total", "Transactions whose deadline passed before they could start", c.expired},
         {"fieldbridge_line_transmitted_bytes_total", "Bytes written to the port", c.bytes_tx},
         {"fieldbridge_line_received_bytes_total", "Bytes read from the port", c.bytes_rx},
         {"fieldbridge_line_reopens_total", "Times the port was reopened after an error", worker.reopens()}});
    out.add_counter("fieldbridge_line_busy_seconds_total",
                    "Time the line carried a transaction; rate() of it is the line's utilisation (0..1)", line,
                    as_seconds(c.busy_time));
    out.add_histogram("fieldbridge_line_transaction_duration_seconds",
                      "Duration of every transaction written to the line, from start to reply, timeout or the "
                      "broadcast's silence",
                      line, to_histogram(worker.master().latency()));
}

void collect_device(MetricSet& out, const engine::LineWorker& worker, const engine::DeviceAgent& agent,
                    core::UnitId unit_id) {
    const Labels device{{"line", worker.config().name},
                        {"device", agent.config().name},
                        {"unit", std::to_string(unit_id.value)}};
    out.add_gauge("fieldbridge_device_online", "1 while the device answers, 0 once it is offline", device,
                  agent.online() ? 1 : 0);
    const engine::DeviceStats* stats = worker.scheduler().stats(agent.config().index);
    if (stats == nullptr) return;
    out.add_counters(device, {{"fieldbridge_device_exceptions_total",
                               "Valid replies that were Modbus exception responses", stats->device_exceptions},
                              {"fieldbridge_device_went_offline_total", "Times the device was declared offline",
                               stats->went_offline}});
    for (std::size_t k = 0; k < engine::priority_count; ++k) {
        const engine::ClassStats& cs = stats->by_class[k];
        Labels labels = device;
        labels.push_back({"class", priority_labels[k]});
        out.add_counters(
            labels,
            {{"fieldbridge_device_requests_total", "Transactions submitted for the device", cs.submitted},
             {"fieldbridge_device_retries_total", "Reads queued again after a timeout", cs.retries},
             {"fieldbridge_device_timeouts_total", "Transactions that ended without a reply (after retries)",
              cs.outcome(engine::OutcomeStatus::timeout)},
             {"fieldbridge_device_expired_total", "Transactions whose deadline passed before they were sent",
              cs.outcome(engine::OutcomeStatus::expired)},
             {"fieldbridge_device_queue_full_total", "Transactions refused because the device's queue was full",
              cs.outcome(engine::OutcomeStatus::queue_full)}});
        out.add_gauge("fieldbridge_device_queue_depth", "Transactions queued for the device now", labels,
                      static_cast<double>(cs.depth));
        out.add_histogram("fieldbridge_device_queue_wait_seconds",
                          "Time from queueing a transaction to its start on the line", labels,
                          to_histogram(cs.wait));
    }
}

}  // namespace

void collect_engine(MetricSet& out, const engine::Engine& engine) {
    for (const engine::LineEntry& line : engine.lines()) collect_line(out, *line.worker);
    for (const engine::LineEntry& line : engine.lines()) {
        for (const auto& agent : line.agents) {
            for (const engine::DeviceEntry& entry : engine.devices()) {
                if (entry.agent == agent.get()) collect_device(out, *line.worker, *agent, entry.unit_id);
            }
        }
    }
}

}  // namespace fieldbridge::northbound::metrics
