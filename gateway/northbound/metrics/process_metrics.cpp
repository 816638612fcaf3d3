#include "northbound/metrics/process_metrics.hpp"

namespace fieldbridge::northbound::metrics {

void collect_reloads(MetricSet& out, std::uint64_t ok, std::uint64_t rejected) {
    constexpr const char* help = "Configuration reloads (SIGHUP), by result: ok applied, rejected kept the old one";
    out.add_counter("fieldbridge_reloads_total", help, {{"result", "ok"}}, static_cast<double>(ok));
    out.add_counter("fieldbridge_reloads_total", help, {{"result", "rejected"}}, static_cast<double>(rejected));
}

}  // namespace fieldbridge::northbound::metrics
