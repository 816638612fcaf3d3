#pragma once
/// @file stall_probe.hpp
/// How late this machine runs a thread that asked to wake at a given instant: a
/// thread sleeps to absolute instants 1 ms apart (clock_nanosleep, timer slack 1 ns)
/// and records how late each wake-up came. A latency figure of the gateway whose
/// excess over its ideal is within the probe's maximum over the same window may be
/// the machine's, not the gateway's: the write-latency parts print both
/// (docs/performance.md, "Stall probe"). Costs one wake-up per millisecond.
#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

namespace fieldbridge::bench {

struct StallFigures {
    std::size_t wakeups = 0;
    double p50_us = 0.0;  ///< lateness of the wake-ups
    double p99_us = 0.0;
    double max_us = 0.0;
};

/// Prints "<bench> stall probe: ..." with the wake-ups' lateness beside @p excess_ms,
/// how far a latency's maximum exceeded its ideal.
void print_stall(const char* bench, const StallFigures& stall, double excess_ms);

class StallProbe {
public:
    /// Starts the probe thread.
    StallProbe();
    ~StallProbe();
    StallProbe(const StallProbe&) = delete;
    StallProbe& operator=(const StallProbe&) = delete;

    /// Stops the thread (idempotent) and returns what it saw.
    StallFigures stop();

private:
    void run();

    std::atomic<bool> stopping_{false};
    std::vector<double> late_us_;  ///< written by the thread until stop() joins it
    std::thread thread_;
};

}  // namespace fieldbridge::bench
