#include "stall_probe.hpp"

#include <sys/prctl.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>

#include "percentile.hpp"

namespace fieldbridge::bench {

namespace {

using Clock = std::chrono::steady_clock;
constexpr auto period = std::chrono::milliseconds{1};

}  // namespace

void print_stall(const char* bench, const StallFigures& stall, double excess_ms) {
    std::printf("%s stall probe (a thread sleeping to instants 1 ms apart, over the same window): %zu wake-ups, late "
                "p50 %.0f us, p99 %.0f us, max %.3f ms; ",
                bench, stall.wakeups, stall.p50_us, stall.p99_us, stall.max_us / 1000.0);
    if (excess_ms <= 0.0) {
        std::printf("the latency maximum is within its ideal\n");
    } else {
        std::printf("the latency maximum exceeds its ideal by %.3f ms, %s\n", excess_ms,
                    excess_ms <= stall.max_us / 1000.0 ? "within the machine's worst stall"
                                                       : "more than the machine's worst stall");
    }
}

StallProbe::StallProbe() : thread_([this] { run(); }) {}

StallProbe::~StallProbe() { static_cast<void>(stop()); }

void StallProbe::run() {
    // The slack the line worker sets: the probe measures the machine, not the slack.
    ::prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
    late_us_.reserve(1 << 16);
    Clock::time_point next = Clock::now() + period;
    while (!stopping_.load(std::memory_order_relaxed)) {
        const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(next.time_since_epoch()).count();
        const timespec at{static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
        while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &at, nullptr) == EINTR) {
        }
        const Clock::time_point woke = Clock::now();
        late_us_.push_back(std::chrono::duration<double, std::micro>(woke - next).count());
        // After a stall the next instant is a period from now: one stall, one sample.
        next = std::max(next + period, woke + period / 2);
    }
}

StallFigures StallProbe::stop() {
    stopping_ = true;
    if (thread_.joinable()) thread_.join();
    const Spread late = spread_of(late_us_);
    return StallFigures{late.count, late.p50, late.p99, late.max};
}

}  // namespace fieldbridge::bench
