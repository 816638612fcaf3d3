#include "bus_stats.hpp"

namespace fieldbridge::sim::runtime {
namespace {

double us(std::chrono::nanoseconds d) { return static_cast<double>(d.count()) / 1e3; }

}  // namespace

nlohmann::json to_json(const DeviceCounters& c) {
    return {{"frames", c.frames},
            {"replies", c.replies},
            {"ignored_dead", c.ignored_dead},
            {"dropped", c.dropped},
            {"corrupted", c.corrupted},
            {"truncated", c.truncated},
            {"delayed", c.delayed},
            {"garbage_injected", c.garbage_injected}};
}

nlohmann::json to_json(const WireCounters& c) {
    const auto& t = c.timing;
    const double mean = t.writes == 0 ? 0.0 : us(t.late_sum) / static_cast<double>(t.writes);
    return {{"requests", c.requests},
            {"broadcasts", c.broadcasts},
            {"unanswered", c.unanswered},
            {"replies", c.replies},
            {"bytes_in", c.bytes_in},
            {"bytes_out", c.bytes_out},
            {"busy_ms", us(c.busy) / 1e3},
            {"gap_violations", c.gap_violations},
            {"min_silence_us", c.min_silence.count() < 0 ? nlohmann::json(nullptr)
                                                         : nlohmann::json(us(c.min_silence))},
            {"garbage_bytes", c.garbage_bytes},
            {"crc_errors", c.crc_errors},
            {"collisions", c.collisions},
            {"collision_bytes", c.collision_bytes},
            {"echoes", c.echoes},
            {"dropped", c.dropped},
            {"tx_overflow_bytes", c.tx_overflow_bytes},
            {"unplugs", c.unplugs},
            {"timing",
             {{"writes", t.writes},
              {"late_us_mean", mean},
              {"late_us_max", us(t.late_max)},
              {"late_over_100us", t.late_over_100us},
              {"late_over_1ms", t.late_over_1ms}}}};
}

}  // namespace fieldbridge::sim::runtime
