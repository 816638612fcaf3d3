// Benchmark of the line engine (issue 3, spec section 9): the real engine::Engine,
// built from YAML by the real loader, against `fieldbridge-sim --wire-time` on a
// pseudo-terminal (one HIWIN XEG, 1 ms device turnaround, 115200 bit/s or the baud
// given).
//
//   fb_bench_line [seconds=5] [writes=200] [baud=115200]
//
//   a. line utilisation: 16 on-demand FC04 0x0300 x2 reads kept outstanding
//      (max_age 0), completed transactions/s against 1 / T_line and against the
//      floor;
//   c. CPU per serial transaction: getrusage(RUSAGE_SELF) over each window of (a);
//   0. the floor: the same reads from a minimal master on raw system calls
//      (raw_master.hpp) against a second line of the same simulator (line-floor),
//      what this machine, its pseudo-terminals and the simulator allow at best.
//      (a)/(c) and the floor alternate (floor_pairs.hpp): three pairs of a floor
//      window (the engine idle: its reads stopped and drained, its polls 60 min
//      apart) and then an engine window on line-a (the 16 reads resumed, 200 ms of
//      warm-up), each `seconds` long. Every pair is printed with its two ratios; the
//      figures are the medians of the pairs' ratios, since this machine's CPU per
//      transaction moves twofold from minute to minute. The simulator's physics is
//      checked from the master's side over the first floor window
//      (floor_report.hpp);
//   b. command latency: then the same saturating reads plus one FC16 write every
//      30-50 ms (random phase), submit -> answer latency against the priority ideal.
//
// The simulator binary is named by FIELDBRIDGE_SIM (run-benchmarks sets it); it is a
// separate process, so the CPU figure is the gateway side alone (engine, scheduler,
// line I/O and this load generator's callbacks). Not a test: it prints figures and
// asserts nothing. Lines whose figures the summary of tests/bench/run-benchmarks
// collects start with "summary:".

#include <algorithm>
#include <asio/steady_timer.hpp>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "floor_pairs.hpp"
#include "floor_report.hpp"
#include "line_limit.hpp"
#include "load_shape.hpp"
#include "percentile.hpp"
#include "process_cpu.hpp"
#include "raw_master.hpp"
#include "read_load.hpp"
#include "engine_harness.hpp"
#include "sim_process.hpp"
#include "stall_probe.hpp"

namespace {

using namespace fieldbridge;
using integration::EngineHarness;
using test::SimProcess;
using Clock = std::chrono::steady_clock;
using std::chrono::duration;
using std::chrono::milliseconds;
using std::chrono::seconds;

constexpr unsigned outstanding_reads = 16;
constexpr std::uint16_t status_address = 0x0300;  // position + status, input registers
constexpr std::uint16_t speed_address = 0x0631;   // "move: speed": a parameter, moves nothing alone

double ms(Clock::duration d) { return duration<double, std::milli>(d).count(); }

std::string engine_yaml(const std::string& port, std::uint32_t baud) {
    // Polls slowed down so that (a) measures the on-demand reads alone; max_age 0: every
    // read goes to the line; a queue long enough for the readers and the writes.
    // FIELDBRIDGE_BENCH_PRECISE_TIMING=true|false sets the line's precise_timing
    // (docs/configuration.md); unset: the default.
    const char* precise = std::getenv("FIELDBRIDGE_BENCH_PRECISE_TIMING");
    const std::string precise_line = precise != nullptr ? fmt::format("\n    precise_timing: {}", precise) : "";
    return fmt::format(R"(
gateway: {{ id: bench-line }}
lines:
  - name: line-a
    port: {}
    baud: {}
    turnaround: 0ms{}
    devices:
      - name: xeg
        type: hiwin-xeg
        address: 2
        unit_id: 1
        max_age: 0ms
        queue_limit: 64
        command_ttl: 1s
        poll: {{ fast: 60min, slow: 60min, motion: 60min }}
)",
                       port, baud, precise_line);
}

int run(double run_seconds, int write_count, std::uint32_t baud) {
    const bench::LoadShape shape(bench::LoadShape::Kind::xeg);
    const auto turnaround = milliseconds{1};
    const bench::LineLimit limit = bench::line_limit(shape, baud, turnaround);
    const double t_read = limit.t_read_ms;
    const double t_write = limit.t_write_ms;
    const double limit_tps = limit.limit_tps;

    // line-a for the engine, line-floor (the same device) for the floor.
    SimProcess sim({"--bus", "{dir}/line-a:hiwin-xeg@2", "--bus", "{dir}/line-floor:hiwin-xeg@2", "--wire-time",
                    "--baud", std::to_string(baud), "--turnaround", "1ms"});

    EngineHarness h(engine_yaml(sim.path("line-a"), baud));
    h.start();
    // The floor keeps the silence the way the engine's line does: slept out, or with
    // precise_timing slept to the lead and spun (raw_master.hpp).
    const engine::Duration spin_lead = h.engine().lines().front().worker->config().spin_lead;
    auto& xeg = h.device("xeg");
    if (!h.run_until([&] { return xeg.online(); }, seconds{5})) {
        std::fprintf(stderr, "fb_bench_line: the XEG did not come online within 5 s\n%s\n", sim.log_text().c_str());
        return 1;
    }

    // ---- 0, a, c: the floor and the engine in alternating windows --------------------
    // One window of either moves by +-20 % (and the floor's CPU twofold between
    // minutes) on this virtual machine with the same code: each pair is a floor window
    // and the engine window right after it, every ratio is taken within its pair, and
    // the figures are medians.
    constexpr int pairs = 3;
    const duration<double> window(run_seconds);
    std::printf("== fb_bench_line (0, a, c) the floor (minimal raw-syscall master on line-floor, the engine idle) and "
                "the engine (16 reads outstanding on line-a), %d alternating pairs of %.1f s windows, %u bit/s ==\n",
                pairs, run_seconds, baud);
    const auto counter = [](const nlohmann::json& bus, const char* name) { return bus.value(name, std::uint64_t{0}); };
    bench::ReadLoad reads(xeg, status_address);
    bench::FloorPairs floor_pairs;
    std::vector<double> window_tps;
    std::vector<double> window_cpu;
    double user_total = 0.0;
    double sys_total = 0.0;
    double elapsed = 0.0;
    std::uint64_t transactions = 0;
    std::uint64_t sim_requests = 0;
    std::uint64_t sim_replies = 0;
    for (int pair = 1; pair <= pairs; ++pair) {
        // The engine is idle here: its reads drained (below), its polls 60 min apart,
        // and its loop does not run while the floor has this thread.
        const bench::RawMasterResult floor = bench::run_raw_master(
            bench::RawMasterSetup{sim.path("line-floor"), shape, baud, turnaround, window, spin_lead});
        if (pair == 1) {
            std::printf("the first floor window:\n");
            bench::print_floor("fb_bench_line", floor, limit);
        }

        reads.start(outstanding_reads);
        h.run_for(milliseconds{200});  // warm-up
        const auto bus0 = sim.stats()["buses"]["line-a"];
        const std::uint64_t before = reads.completed();
        const bench::CpuTimes cpu0 = bench::process_cpu();
        const auto w0 = Clock::now();
        h.run_for(std::chrono::duration_cast<engine::Duration>(window));
        const auto w1 = Clock::now();
        const bench::CpuTimes cpu1 = bench::process_cpu();
        const std::uint64_t done = reads.completed() - before;
        const auto bus1 = sim.stats()["buses"]["line-a"];
        reads.stop();
        if (!h.run_until([&] { return reads.in_flight() == 0; }, seconds{5})) {
            std::fprintf(stderr, "fb_bench_line: %u reads still outstanding 5 s after the window\n",
                         reads.in_flight());
            return 1;
        }

        const double seconds_in_window = duration<double>(w1 - w0).count();
        const double cpu = (cpu1.user - cpu0.user) + (cpu1.sys - cpu0.sys);
        window_tps.push_back(static_cast<double>(done) / seconds_in_window);
        window_cpu.push_back(done > 0 ? cpu * 1e6 / static_cast<double>(done) : 0.0);
        user_total += cpu1.user - cpu0.user;
        sys_total += cpu1.sys - cpu0.sys;
        elapsed += seconds_in_window;
        transactions += done;
        sim_requests += counter(bus1, "requests") - counter(bus0, "requests");
        sim_replies += counter(bus1, "replies") - counter(bus0, "replies");
        floor_pairs.add("fb_bench_line", "engine",
                        bench::FloorPair{{bench::floor_rate(floor), bench::floor_cpu_us(floor)},
                                         {window_tps.back(), window_cpu.back()}});
    }
    const auto bus_end = sim.stats()["buses"]["line-a"];
    const bench::WindowFigures engine_median = floor_pairs.median_gateway();
    const bench::WindowFigures floor_median = floor_pairs.median_floor();
    const double tps = engine_median.tps;
    const double cpu_us = engine_median.cpu_us;
    const auto list = [](const std::vector<double>& values, const char* format) {
        std::string text;
        for (const double value : values) text += (text.empty() ? "" : ", ") + fmt::format(fmt::runtime(format), value);
        return text;
    };

    std::printf("== fb_bench_line (a) line utilisation: 16 on-demand FC04 0x0300 x2 reads outstanding ==\n");
    std::printf("T_line (8 + 9 bytes, %u 8N1, 1 ms turnaround) = %.3f ms -> limit %.1f tx/s\n", baud, t_read,
                limit_tps);
    std::printf("completed %llu reads in %d windows, %.3f s; median window %.1f tx/s, ratio %.3f (target >= 0.95); "
                "failed %llu; median pair ratio to the floor %.3f; windows: %s tx/s\n",
                static_cast<unsigned long long>(transactions), pairs, elapsed, tps, tps / limit_tps,
                static_cast<unsigned long long>(reads.failed()), floor_pairs.median_rate_ratio(),
                list(window_tps, "{:.1f}").c_str());
    std::printf("simulator: %llu requests, %llu replies in the windows; gap_violations total %llu (target 0), "
                "min_silence_us %s, collisions %llu, utilization %s\n",
                static_cast<unsigned long long>(sim_requests), static_cast<unsigned long long>(sim_replies),
                static_cast<unsigned long long>(counter(bus_end, "gap_violations")),
                bus_end.contains("min_silence_us") ? bus_end["min_silence_us"].dump().c_str() : "?",
                static_cast<unsigned long long>(counter(bus_end, "collisions")),
                bus_end.contains("utilization") ? bus_end["utilization"].dump().c_str() : "?");
    // Where the time between transactions goes: how late the simulator's replies left
    // (its own scheduling), against the silence the master actually kept.
    const double per_tx_ms = transactions > 0 ? elapsed * 1000.0 / static_cast<double>(transactions) : 0.0;
    std::printf("mean line time per transaction %.3f ms = T_line + %.3f ms; simulator reply lateness %s\n",
                per_tx_ms, per_tx_ms - t_read, bus_end.contains("timing") ? bus_end["timing"].dump().c_str() : "?");
    std::printf("== fb_bench_line (c) CPU per serial transaction ==\n");
    std::printf("process CPU (user+sys) per transaction, median of %d windows = %.1f us/transaction (target <= 50); "
                "windows: %s us; median pair ratio to the floor %.2fx (target <= 1.3); user %.0f %% / kernel %.0f %% "
                "(tick-sampled split)\n",
                pairs, cpu_us, list(window_cpu, "{:.1f}").c_str(), floor_pairs.median_cpu_ratio(),
                100.0 * user_total / (user_total + sys_total), 100.0 * sys_total / (user_total + sys_total));
    std::printf("summary: engine line rate xeg at %u bit/s: %.1f tx/s = %.3f of the limit (target >= 0.95), %.3f of "
                "the floor (median of %zu pair ratios; floor median %.3f of the limit); CPU %.1f us/transaction "
                "(median of %zu windows) = %.2fx the floor (median of the pair ratios, target <= 1.3; floor median "
                "%.1f us)\n",
                baud, tps, tps / limit_tps, floor_pairs.median_rate_ratio(), floor_pairs.size(),
                floor_median.tps / limit_tps, cpu_us, floor_pairs.size(), floor_pairs.median_cpu_ratio(),
                floor_median.cpu_us);

    // ---- b: command latency under saturating reads --------------------------------
    std::vector<double> latencies;
    int write_failures = 0;
    int submitted = 0;
    std::mt19937 random(20261124);
    std::uniform_int_distribution<int> gap_us(30'000, 50'000);
    asio::steady_timer timer(h.io());
    std::function<void()> schedule = [&] {
        timer.expires_after(std::chrono::microseconds{gap_us(random)});
        timer.async_wait([&](const std::error_code& ec) {
            if (ec || submitted >= write_count) return;
            const auto value = static_cast<std::uint16_t>(1000 + (submitted % 2));
            ++submitted;
            const auto sent = Clock::now();
            xeg.request(protocol::WriteMultipleRegistersRequest{speed_address, {value}},
                        [&, sent](const protocol::Response& response) {
                            if (std::holds_alternative<protocol::WriteMultipleResponse>(response)) {
                                latencies.push_back(ms(Clock::now() - sent));
                            } else {
                                ++write_failures;
                            }
                        });
            schedule();
        });
    };
    reads.start(outstanding_reads);
    h.run_for(milliseconds{200});  // warm-up
    const std::uint64_t b_done0 = reads.completed();
    const auto b0 = Clock::now();
    bench::StallProbe probe;
    schedule();
    h.run_until([&] { return static_cast<int>(latencies.size()) + write_failures >= write_count; },
                seconds{write_count / 10 + 10}, milliseconds{50});
    const bench::StallFigures stall = probe.stop();
    const auto b1 = Clock::now();
    const double b_tps = static_cast<double>(reads.completed() - b_done0) / duration<double>(b1 - b0).count();
    timer.cancel();
    reads.stop();
    h.run_for(milliseconds{200});

    const double ideal_p50 = t_write + t_read / 2.0;
    const double ideal_max = t_write + t_read;
    const bench::Spread latency = bench::spread_of(latencies);
    const double p50 = latency.p50;
    const double p99 = latency.p99;
    const double max = latency.max;
    std::printf("== fb_bench_line (b) write latency with 16 reads outstanding ==\n");
    std::printf("write FC16 x1 (11 + 8 bytes): T_write = %.3f ms; priority ideal p50 = T_write + T_read/2 = %.3f ms, "
                "max = T_write + T_read = %.3f ms\n",
                t_write, ideal_p50, ideal_max);
    std::printf("%zu writes ok, %d failed; reads meanwhile %.1f tx/s\n", latencies.size(), write_failures, b_tps);
    std::printf("latency p50 %.3f ms, p99 %.3f ms, max %.3f ms\n", p50, p99, max);
    std::printf("ratios to the recomputed ideal: p50 %.2f (target <= 1.1), max %.2f (target <= 1.3)\n",
                p50 / ideal_p50, max / ideal_max);
    std::printf("ratios to the spec's figures (4.67 / 6.21 ms): p50 %.2f, max %.2f\n", p50 / 4.67, max / 6.21);
    bench::print_stall("fb_bench_line", stall, max - ideal_max);
    std::printf("summary: engine write xeg at %u bit/s under 16 reads: p50 %.3f ms = %.2fx the priority ideal "
                "(target <= 1.1), max %.3f ms = %.2fx (target <= 1.3); machine stall max %.3f ms\n",
                baud, p50, p50 / ideal_p50, max, max / ideal_max, stall.max_us / 1000.0);
    const auto bus2 = sim.stats()["buses"]["line-a"];
    std::printf("simulator gap_violations after (b): %llu\n",
                static_cast<unsigned long long>(counter(bus2, "gap_violations")));

    h.stop();
    sim.terminate();
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        const double seconds_arg = argc > 1 ? std::atof(argv[1]) : 5.0;
        const int writes_arg = argc > 2 ? std::atoi(argv[2]) : 200;
        const long baud_arg = argc > 3 ? std::atol(argv[3]) : 115200;
        if (seconds_arg <= 0.0 || writes_arg <= 0 || baud_arg <= 0) {
            std::fprintf(stderr, "usage: fb_bench_line [seconds>0] [writes>0] [baud>0]\n");
            return 2;
        }
        return run(seconds_arg, writes_arg, static_cast<std::uint32_t>(baud_arg));
    } catch (const std::exception& e) {
        std::fprintf(stderr, "fb_bench_line: %s\n", e.what());
        return 1;
    }
}
