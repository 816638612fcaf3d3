#include "app/engine_diag.hpp"

#include <array>

namespace fieldbridge::app {

namespace {

using nlohmann::json;

[[nodiscard]] double ms(engine::Duration d) {
    return std::chrono::duration<double, std::milli>(d).count();
}

[[nodiscard]] json percentiles(const engine::LatencyHistogram& h) {
    return json{{"count", h.count()},
                {"p50", ms(h.quantile_upper_bound(0.50))},
                {"p90", ms(h.quantile_upper_bound(0.90))},
                {"p99", ms(h.quantile_upper_bound(0.99))},
                {"max", ms(h.max())}};
}

constexpr std::array<const char*, engine::priority_count> class_names{"command", "on_demand", "poll"};

}  // namespace

json EngineDiag::collect(const engine::Engine& eng, engine::TimePoint now) {
    json lines = json::array();
    for (const engine::LineEntry& line : eng.lines()) {
        const engine::LineWorker& worker = *line.worker;
        const std::string& name = worker.config().name;
        const engine::LineCounters& c = worker.master().counters();
        json out{{"name", name},
                 {"up", worker.line_up()},
                 {"requests", c.requests},
                 {"replies", c.replies},
                 {"timeouts", c.timeouts},
                 {"crc_errors", c.crc_errors},
                 {"wrong_address", c.wrong_address},
                 {"bad_replies", c.bad_replies},
                 {"garbage_bytes", c.garbage_bytes},
                 {"echo_mismatch", c.echo_mismatch},
                 {"broadcasts", c.broadcasts},
                 {"expired", c.expired},
                 {"reopens", worker.reopens()},
                 {"latency_ms", percentiles(worker.master().latency())}};
        // Utilisation: the share of wall time the line carried a transaction since
        // the previous snapshot (the first one counts from zero at start).
        auto& previous = last_[name];
        const engine::Duration wall = previous.at == engine::TimePoint{} ? engine::Duration{} : now - previous.at;
        double utilisation = 0.0;
        if (wall > engine::Duration{} && c.busy_time >= previous.busy) {
            utilisation = 100.0 * ms(c.busy_time - previous.busy) / ms(wall);
        }
        out["utilisation_pct"] = utilisation;
        previous = Busy{c.busy_time, now};

        std::array<std::size_t, engine::priority_count> depth{};
        std::uint64_t line_exceptions = 0;
        json devices = json::array();
        for (const auto& agent : line.agents) {
            const engine::DeviceStats* stats = worker.scheduler().stats(agent->config().index);
            json d{{"name", agent->config().name}, {"online", agent->online()}};
            for (const engine::DeviceEntry& entry : eng.devices()) {
                if (entry.agent == agent.get()) d["unit_id"] = entry.unit_id.value;
            }
            if (stats != nullptr) {
                std::uint64_t submitted = 0;
                std::uint64_t timeouts = 0;
                std::uint64_t expired = 0;
                std::uint64_t queue_full = 0;
                json queue = json::object();
                json wait = json::object();
                for (std::size_t k = 0; k < engine::priority_count; ++k) {
                    const engine::ClassStats& cs = stats->by_class[k];
                    submitted += cs.submitted;
                    timeouts += cs.outcome(engine::OutcomeStatus::timeout);
                    expired += cs.outcome(engine::OutcomeStatus::expired);
                    queue_full += cs.outcome(engine::OutcomeStatus::queue_full);
                    queue[class_names[k]] = cs.depth;
                    wait[class_names[k]] = percentiles(cs.wait);
                    depth[k] += cs.depth;
                }
                d["requests"] = submitted;
                d["timeouts"] = timeouts;
                d["expired"] = expired;
                d["queue_full"] = queue_full;
                d["went_offline"] = stats->went_offline;
                d["exceptions"] = stats->device_exceptions;
                line_exceptions += stats->device_exceptions;
                d["queue"] = std::move(queue);
                d["wait_ms"] = std::move(wait);
            }
            devices.push_back(std::move(d));
        }
        json queue = json::object();
        for (std::size_t k = 0; k < engine::priority_count; ++k) queue[class_names[k]] = depth[k];
        out["queue"] = std::move(queue);
        out["exceptions"] = line_exceptions;
        out["devices"] = std::move(devices);
        lines.push_back(std::move(out));
    }
    return json{{"lines", std::move(lines)}};
}

}  // namespace fieldbridge::app
