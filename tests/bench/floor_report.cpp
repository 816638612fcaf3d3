#include "floor_report.hpp"

#include <cstdio>
#include <string>

namespace fieldbridge::bench {

double floor_rate(const RawMasterResult& floor) noexcept {
    return floor.seconds > 0.0 ? static_cast<double>(floor.transactions) / floor.seconds : 0.0;
}

double floor_cpu_us(const RawMasterResult& floor) noexcept { return floor.user_cpu_us + floor.sys_cpu_us; }

void print_floor(const char* bench, const RawMasterResult& floor, const LineLimit& limit) {
    const double rate = floor_rate(floor);
    std::printf("%s floor: %llu reads in %.3f s = %.1f tx/s, floor's limit ratio %.3f (limit %.1f tx/s at %u bit/s); "
                "%llu timeouts; CPU %.1f us/transaction (user %.1f + kernel %.1f)\n",
                bench, static_cast<unsigned long long>(floor.transactions), floor.seconds, rate,
                rate / limit.limit_tps, limit.limit_tps, limit.baud, static_cast<unsigned long long>(floor.timeouts),
                floor_cpu_us(floor), floor.user_cpu_us, floor.sys_cpu_us);
    // The simulator's model delivers a reply t3.5 (its end-of-frame silence) after the
    // request, plus the turnaround and the reply's own wire time.
    const double model_ms = floor.reply_bound_ms + limit.t3_5_us / 1000.0;
    std::printf("%s physics: reply readable after the request's write began: min %.3f ms, median %.3f ms, "
                "p99 %.3f ms; physical bound (request + turnaround + reply on the wire) %.3f ms: %llu of %llu "
                "replies earlier (must be 0); the simulator's model (+ t3.5 end of frame) %.3f ms, median +%.0f us\n",
                bench, floor.reply_min_ms, floor.reply_median_ms, floor.reply_p99_ms, floor.reply_bound_ms,
                static_cast<unsigned long long>(floor.early_replies),
                static_cast<unsigned long long>(floor.transactions), model_ms,
                (floor.reply_median_ms - model_ms) * 1e3);
    const std::string method =
        floor.spin_lead_us > 0.0
            ? "slept to " + std::to_string(static_cast<long>(floor.spin_lead_us)) +
                  " us before its end, then spun, as precise_timing does"
            : std::string("slept with clock_nanosleep()");
    std::printf("%s physics: the master's silence from the reply read to its next write: min %.0f us, "
                "median %.0f us, p99 %.0f us (t3.5 = %.0f us; %s)\n",
                bench, floor.silence_min_us, floor.silence_median_us, floor.silence_p99_us, limit.t3_5_us,
                method.c_str());
}

}  // namespace fieldbridge::bench
