// Benchmark of the whole gateway over Modbus TCP (issues 4 and 14, spec section 9):
// the real `fieldbridge` daemon on a generated configuration, its lines on
// `fieldbridge-sim --wire-time` pseudo-terminals (1 ms device turnaround), and the
// load-generating clients in this process (tcp_load.hpp).
//
//   FIELDBRIDGE_SIM=<fieldbridge-sim> fb_bench_tcp_daemon <fieldbridge> [seconds=5] [writes=200]
//       [--shape=xeg|generic] [--baud=115200] [--clients=16[,8,...]]
//       [--parts=cache,line,scrape,write] [--paced-runs=3]
//
//   the floor: the minimal raw-syscall master (raw_master.hpp) reads the same shape
//      on line-floor of the same simulator at the same baud, in windows of
//      `seconds`/2 while the daemon is idle (no client runs; with `cache`, line-a's
//      polls go on). Every line figure is printed as a ratio to the physical limit
//      and to a floor window measured seconds before it, never minutes: this
//      machine's CPU per transaction moves twofold from minute to minute. The
//      simulator's physics is checked from the master's side over the first floor
//      window (floor_report.hpp);
//   cache, 1. cache-served reads: 32 clients (blocking sockets, one request
//      outstanding each) read FC04 0x0300 x2 from unit 1 (line-a, one XEG, max_age
//      10s, polled every 100 ms) flat out: reads/s, p50/p99, and the serial requests
//      the simulator saw during the load against an idle window before it;
//   cache, 1b. the same reads offered at 50,000/s by one epoll thread driving 32
//      connections (paced_reads.hpp), latency from when due; against a null server
//      in this process first (the generator's own tail), then against the daemon;
//      `--paced-runs` times each, alternated;
//   line, 2. TCP -> line throughput: N clients (each of `--clients`) read the shape
//      from line-b (max_age 0: every read goes to the line), in three alternating
//      pairs (floor_pairs.hpp) of a floor window and then the clients' window, each
//      `seconds`/2 long (half, to keep tests/bench/run-benchmarks' eight loads
//      within minutes); every pair is printed with its rate and CPU ratios, and the
//      summary gives the medians of the pair ratios;
//   scrape, 2b/2c. a floor window, then the first of those loads for `seconds` while
//      /metrics is scraped every 100 ms, then once more without; their ratios are to
//      that floor window;
//   write, 3. a floor window, then command latency under load: 16 clients saturate
//      line-b while a 17th writes FC06 every 30-50 ms: send -> answer against the
//      priority ideal; the line rate meanwhile against that floor window.
//
// Shapes (load_shape.hpp): `xeg`, one HIWIN XEG on line-b, FC04 0x0300 x2; `generic`,
// four generic `modbus` devices on line-b, FC03 x2 at varying addresses.
//
// Clients and daemon share the machine's cores: the figures include that contention.
// The blocking client threads run at nice 10: they stand for other machines, and at
// nice 0 the 32 of them starve the device simulator. The daemon, the simulator and
// the paced generator run at the default priority. Lines whose figures the summary of
// tests/bench/run-benchmarks collects start with "summary:".
// Not a test: it prints figures and asserts nothing.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "config/validate.hpp"
#include "daemon_process.hpp"
#include "floor_pairs.hpp"
#include "floor_report.hpp"
#include "line_limit.hpp"
#include "load_shape.hpp"
#include "loopback_port.hpp"
#include "metrics_scraper.hpp"
#include "null_modbus_server.hpp"
#include "paced_reads.hpp"
#include "percentile.hpp"
#include "raw_master.hpp"
#include "sim_process.hpp"
#include "stall_probe.hpp"
#include "tcp_load.hpp"

namespace {

using namespace fieldbridge;
using bench::ClientResult;
using bench::LoadFigures;
using bench::LoadShape;
using bench::Target;
using bench::run_client;
using bench::run_load;
using bench::run_writer;
using Clock = std::chrono::steady_clock;
using std::chrono::duration;
using std::chrono::milliseconds;

constexpr auto turnaround = milliseconds{1};  // the simulator's device turnaround

struct Options {
    std::string daemon;
    double seconds = 5.0;
    int writes = 200;
    LoadShape shape{LoadShape::Kind::xeg};
    std::uint32_t baud = 115200;
    std::vector<unsigned> clients{16};
    std::vector<std::string> parts{"cache", "line", "scrape", "write"};
    int paced_runs = 3;

    [[nodiscard]] bool has(std::string_view part) const {
        return std::find(parts.begin(), parts.end(), part) != parts.end();
    }
};

std::string daemon_yaml(const Options& options, std::uint16_t port, std::uint16_t metrics_port,
                        const std::string& line_a, const std::string& line_b) {
    std::string cached_line;
    if (options.has("cache")) {
        cached_line = fmt::format(R"(  - name: line-a          # cache-served reads: polled, answered from the image
    port: {}
    baud: {}
    turnaround: 0ms
    devices:
      - name: xeg-cached
        type: hiwin-xeg
        address: 2
        unit_id: 1
        max_age: 10s
        poll: {{ fast: 100ms, slow: 1s }}
)",
                                  line_a, options.baud);
    }
    return fmt::format(R"(# Generated by fb_bench_tcp_daemon.
gateway: {{ id: bench, log_level: info }}
modbus_tcp:
  listen: ["127.0.0.1:{}"]
  max_connections: 64
  # Every benchmark client connects from 127.0.0.1: the per-address cap (default 16,
  # docs/modbus-tcp.md) would refuse the 17th.
  max_connections_per_client: 64
metrics_http:
  listen: 127.0.0.1:{}
lines:
{}  - name: line-b          # TCP -> line: every read goes to the device
    port: {}
    baud: {}
    turnaround: 0ms
    devices:
{})",
                       port, metrics_port, cached_line, line_b, options.baud, options.shape.daemon_devices(2));
}

std::uint64_t bus_counter(const test::SimProcess& sim, const char* bus, const char* name) {
    return sim.bus_counter(bus, name);
}

/// Parts 1 and 1b: cache-served reads from line-a's image.
void run_cache(const Options& options, const test::SimProcess& sim, const bench::DaemonProcess& daemon,
               std::uint16_t port) {
    const double seconds = options.seconds;
    // Let the polls fill line-a's image, then measure an idle window: the polls alone.
    std::this_thread::sleep_for(milliseconds{1500});
    const auto idle_requests0 = bus_counter(sim, "line-a", "requests");
    const double idle_cpu0 = daemon.cpu_seconds();
    const auto idle0 = Clock::now();
    std::this_thread::sleep_for(duration<double>(seconds));
    const double idle_elapsed = duration<double>(Clock::now() - idle0).count();
    const double idle_cpu = daemon.cpu_seconds() - idle_cpu0;
    const auto idle_requests = bus_counter(sim, "line-a", "requests") - idle_requests0;
    const double idle_rate = static_cast<double>(idle_requests) / idle_elapsed;

    std::uint64_t a_requests0 = 0;
    std::uint64_t a_requests1 = 0;
    double cached_cpu0 = 0.0;
    double cached_cpu1 = 0.0;
    const Target cached_target{LoadShape(LoadShape::Kind::xeg), 1};
    const auto cached = run_load(port, cached_target, 32, seconds, [&](bool start) {
        (start ? a_requests0 : a_requests1) = bus_counter(sim, "line-a", "requests");
        (start ? cached_cpu0 : cached_cpu1) = daemon.cpu_seconds();
    });
    const double cached_rate = static_cast<double>(cached.reads) / cached.seconds;
    const auto load_requests = a_requests1 - a_requests0;
    std::printf("== fb_bench_tcp_daemon (1) cache-served reads: 32 clients, FC04 0x0300 x2, unit 1 (max_age 10s) ==\n");
    std::printf("%llu reads in %.1f s = %.0f reads/s (target >= 50000); errors %llu%s%s\n",
                static_cast<unsigned long long>(cached.reads), cached.seconds, cached_rate,
                static_cast<unsigned long long>(cached.errors), cached.failures.empty() ? "" : "; client failures: ",
                cached.failures.c_str());
    if (!cached.exceptions.empty()) std::printf("exception replies: %s\n", cached.exceptions.c_str());
    std::printf("latency p50 %.0f us, p99 %.0f us, max %.0f us (32 always outstanding: mostly queueing)\n",
                cached.p50_us, cached.p99_us, cached.max_us);
    std::printf("serial requests on line-a: %llu during the load (%.1f/s) vs %llu in the idle window before "
                "(%.1f/s, polls only): %+.1f/s caused by the reads (target 0)\n",
                static_cast<unsigned long long>(load_requests),
                static_cast<double>(load_requests) / cached.seconds, static_cast<unsigned long long>(idle_requests),
                idle_rate, static_cast<double>(load_requests) / cached.seconds - idle_rate);
    std::printf("daemon CPU during the load: %.2f s of %.1f s (%.0f%% of one core; the clients use the rest)\n",
                cached_cpu1 - cached_cpu0, cached.seconds, 100.0 * (cached_cpu1 - cached_cpu0) / cached.seconds);
    std::printf("daemon idle CPU (line-a polled at 100 ms / 1 s, line-b idle): %.2f%% of one core; RSS %ld KiB\n",
                100.0 * idle_cpu / idle_elapsed, daemon.rss_kib());
    std::printf("summary: cache reads flat out (32 clients): %.0f reads/s, p99 %.0f us; line-a %+.1f requests/s "
                "caused by them\n",
                cached_rate, cached.p99_us, static_cast<double>(load_requests) / cached.seconds - idle_rate);
    daemon.print_warnings("during (1)");

    // ---- 1b: paced at the target rate, null server and daemon alternated ------------
    constexpr double paced_rate = 50'000.0;
    std::printf("== fb_bench_tcp_daemon (1b) cache-served reads offered at %.0f/s: one epoll thread, 32 connections, "
                "latency from when due; a null server in this process, then the daemon ==\n",
                paced_rate);
    bench::NullModbusServer null_server;
    std::vector<double> null_p99;
    std::vector<double> daemon_p99;
    for (int run = 1; run <= options.paced_runs; ++run) {
        for (const bool against_daemon : {false, true}) {
            bench::PacedLoad load;
            load.port = against_daemon ? port : null_server.port();
            load.rate = paced_rate;
            load.window = duration<double>(seconds);
            const auto requests0 = bus_counter(sim, "line-a", "requests");
            const double cpu0 = daemon.cpu_seconds();
            const bench::PacedFigures paced = bench::run_paced_reads(load);
            const double cpu = daemon.cpu_seconds() - cpu0;
            const auto requests = bus_counter(sim, "line-a", "requests") - requests0;
            (against_daemon ? daemon_p99 : null_p99).push_back(paced.p99_us);
            std::printf("run %d %-11s: %llu reads in %.1f s = %.0f reads/s; from when due p50 %.0f us, p99 %.0f us, "
                        "max %.0f us; from when sent p99 %.0f us; sent > 100 us late %llu, unanswered %llu, errors "
                        "%llu%s%s",
                        run, against_daemon ? "daemon" : "null server", static_cast<unsigned long long>(paced.reads),
                        paced.seconds, static_cast<double>(paced.reads) / paced.seconds, paced.p50_us, paced.p99_us,
                        paced.max_us, paced.service_p99_us, static_cast<unsigned long long>(paced.late_sends),
                        static_cast<unsigned long long>(paced.unanswered),
                        static_cast<unsigned long long>(paced.errors), paced.failure.empty() ? "" : "; failed: ",
                        paced.failure.c_str());
            if (against_daemon) {
                std::printf("; daemon CPU %.0f%% of one core; line-a %.1f requests/s (polls alone %.1f/s)",
                            100.0 * cpu / seconds, static_cast<double>(requests) / seconds, idle_rate);
            }
            std::printf("\n");
        }
    }
    std::printf("summary: cache reads paced at 50000/s, p99 from when due (target < 1000 us), median of %d runs: "
                "daemon %.0f us, null server %.0f us\n",
                options.paced_runs, bench::median_of(daemon_p99), bench::median_of(null_p99));
    daemon.print_warnings("during (1b)");
}

struct LineLoad {
    LoadFigures figures;
    double rate = 0.0;
    std::uint64_t requests = 0;
    double cpu_us = 0.0;
};

int run(const Options& options) {
    const double seconds = options.seconds;
    const LoadShape& shape = options.shape;
    const bench::LineLimit limit = bench::line_limit(shape, options.baud, turnaround);
    const std::string baud = std::to_string(options.baud);
    test::SimProcess sim({"--bus", "{dir}/line-a:hiwin-xeg@2", "--bus", "{dir}/line-b:" + shape.sim_devices(),
                                 "--bus", "{dir}/line-floor:" + shape.sim_devices(), "--wire-time", "--baud", baud,
                                 "--turnaround", "1ms"});
    const std::string label = fmt::format("{} at {} bit/s", shape.name(), options.baud);
    std::printf("fb_bench_tcp_daemon: shape %s (%s) at %u bit/s 8N1, 1 ms turnaround; T_line %.3f ms -> limit %.1f "
                "tx/s; t3.5 %.1f us\n",
                std::string(shape.name()).c_str(), std::string(shape.description()).c_str(), options.baud,
                limit.t_read_ms, limit.limit_tps, limit.t3_5_us);

    const bool line_parts = options.has("line") || options.has("scrape") || options.has("write");
    const std::uint16_t port = bench::free_loopback_port();
    const auto config_path = sim.dir() / "bench.yaml";
    const std::uint16_t metrics_port = bench::free_loopback_port();
    std::ofstream(config_path) << daemon_yaml(options, port, metrics_port, sim.path("line-a"), sim.path("line-b"));
    bench::DaemonProcess daemon(options.daemon, config_path, sim.dir() / "fieldbridge.log");

    if (options.has("cache")) run_cache(options, sim, daemon, port);

    // ---- the floor: on line-floor while no client runs ------------------------------
    const double pair_seconds = seconds / 2.0;
    // The floor keeps the silence the way line-b does: its precise_timing is the
    // default for the baud (no turnaround set), so the floor spins when it does.
    config::LineConfig line_b;
    line_b.baud = options.baud;
    const std::chrono::nanoseconds floor_spin_lead =
        config::default_precise_timing(line_b) ? std::chrono::nanoseconds{config::LineConfig::precise_timing_lead}
                                               : std::chrono::nanoseconds::zero();
    int floor_windows = 0;
    double floor_silence_us = 0.0;  // the last floor window's median silence
    const auto floor_window = [&] {
        const bench::RawMasterResult floor = bench::run_raw_master(bench::RawMasterSetup{
            sim.path("line-floor"), shape, options.baud, turnaround, duration<double>(pair_seconds), floor_spin_lead});
        floor_silence_us = floor.silence_median_us;
        if (++floor_windows == 1) {
            std::printf("the first floor window (minimal raw-syscall master on line-floor, %s, the daemon idle):\n",
                        label.c_str());
            bench::print_floor("fb_bench_tcp_daemon", floor, limit);
        }
        return bench::WindowFigures{bench::floor_rate(floor), bench::floor_cpu_us(floor)};
    };
    const auto ratio = [](double value, double floor) { return floor > 0.0 ? value / floor : 0.0; };

    const Target direct_target{shape, 2};
    const auto line_b_load = [&](unsigned clients, double window_seconds) {
        std::uint64_t r0 = 0;
        std::uint64_t r1 = 0;
        double cpu0 = 0.0;
        double cpu1 = 0.0;
        LineLoad load;
        load.figures = run_load(port, direct_target, clients, window_seconds, [&](bool start) {
            (start ? r0 : r1) = bus_counter(sim, "line-b", "requests");
            (start ? cpu0 : cpu1) = daemon.cpu_seconds();
        });
        load.rate = static_cast<double>(load.figures.reads) / load.figures.seconds;
        load.requests = r1 - r0;
        load.cpu_us = r1 == r0 ? 0.0 : (cpu1 - cpu0) * 1e6 / static_cast<double>(r1 - r0);
        return load;
    };
    if (line_parts) std::this_thread::sleep_for(milliseconds{500});  // the generic blocks' first reads

    // ---- 2: TCP -> line throughput, alternating with the floor ----------------------
    constexpr int pairs = 3;
    std::vector<double> unscraped_rates;  // the median rate of each client count
    if (options.has("line") || options.has("scrape")) {
        for (const unsigned clients : options.clients) {
            std::printf("== fb_bench_tcp_daemon (2) TCP -> line: %u clients, %s, max_age 0; %d alternating pairs of "
                        "%.1f s windows: the floor on line-floor (no client running), then the clients on line-b ==\n",
                        clients, label.c_str(), pairs, pair_seconds);
            bench::FloorPairs floor_pairs;
            std::vector<double> ceilings;  // one client: what its round trips leave (bench::closed_loop_ceiling)
            for (int pair = 1; pair <= pairs; ++pair) {
                const bench::WindowFigures floor = floor_window();
                if (clients == 1) {
                    // The same single client against a server that answers at once: its
                    // round trip is what the line waits on after each answer, minus the
                    // silence, whatever the gateway does.
                    bench::NullModbusServer null_server;
                    const LoadFigures round_trip = run_load(null_server.port(), direct_target, 1, 1.0, [](bool) {});
                    ceilings.push_back(bench::closed_loop_ceiling(floor.tps, round_trip.p50_us, floor_silence_us));
                    std::printf("pair %d one client against a null server (1 s): round trip p50 %.0f us, p99 %.0f us; "
                                "the floor's silence %.0f us: the line idles %.0f us per transaction, a ceiling of "
                                "%.3f of the floor for any gateway\n",
                                pair, round_trip.p50_us, round_trip.p99_us, floor_silence_us,
                                std::max(0.0, round_trip.p50_us - floor_silence_us), ceilings.back());
                }
                const LineLoad load = line_b_load(clients, pair_seconds);
                const auto& f = load.figures;
                std::printf("pair %d daemon window: %llu reads answered in %.1f s = %.1f tx/s; errors %llu%s%s; "
                            "simulator line-b requests %.1f/s; latency p50 %.2f ms, p99 %.2f ms, max %.2f ms\n",
                            pair, static_cast<unsigned long long>(f.reads), f.seconds, load.rate,
                            static_cast<unsigned long long>(f.errors), f.failures.empty() ? "" : "; client failures: ",
                            f.failures.c_str(), static_cast<double>(load.requests) / f.seconds, f.p50_us / 1000.0,
                            f.p99_us / 1000.0, f.max_us / 1000.0);
                if (!f.exceptions.empty()) std::printf("exception replies: %s\n", f.exceptions.c_str());
                floor_pairs.add("fb_bench_tcp_daemon", "daemon", bench::FloorPair{floor, {load.rate, load.cpu_us}});
            }
            const bench::WindowFigures daemon_median = floor_pairs.median_gateway();
            const bench::WindowFigures floor_median = floor_pairs.median_floor();
            unscraped_rates.push_back(daemon_median.tps);
            std::printf("summary: TCP->line %s, %u clients: %.1f tx/s (median of %zu windows) = %.3f of the limit "
                        "(target >= 0.95), %.3f of the floor (median of the pair ratios, target >= 0.98; floor median "
                        "%.3f of the limit); daemon CPU %.1f us/transaction (median) = %.2fx the floor (median of the "
                        "pair ratios, target <= 2; floor median %.1f us)\n",
                        label.c_str(), clients, daemon_median.tps, floor_pairs.size(),
                        daemon_median.tps / limit.limit_tps, floor_pairs.median_rate_ratio(),
                        floor_median.tps / limit.limit_tps, daemon_median.cpu_us, floor_pairs.median_cpu_ratio(),
                        floor_median.cpu_us);
            if (!ceilings.empty()) {
                const double ceiling = bench::median_of(std::move(ceilings));
                std::printf("summary: TCP->line %s, 1 client: one request outstanding caps it at %.3f of the floor "
                            "(median of the pairs' closed-loop ceilings); the daemon reached %.3f of that ceiling\n",
                            label.c_str(), ceiling, ratio(floor_pairs.median_rate_ratio(), ceiling));
            }
        }
    }

    // ---- 2b/2c: the same load with and without scraping /metrics ---------------------
    if (options.has("scrape") && !unscraped_rates.empty()) {
        const unsigned clients = options.clients.front();
        const bench::WindowFigures floor = floor_window();
        bench::MetricsScraper scraper(metrics_port, milliseconds{100});
        const LineLoad scraped = line_b_load(clients, seconds);
        const auto scrapes = scraper.stop();
        const LineLoad again = line_b_load(clients, seconds);
        const double first_rate = unscraped_rates.front();
        const double mean = (first_rate + again.rate) / 2.0;
        std::printf("== fb_bench_tcp_daemon (2b) TCP -> line (%u clients) while GET /metrics every 100 ms; (2c) "
                    "again without; both beside the floor window just before (2b): %.1f tx/s, %.1f us/tx ==\n",
                    clients, floor.tps, floor.cpu_us);
        std::printf("scraped %.1f tx/s (%.3f of the limit, %.3f of the floor; p99 %.2f ms, errors %llu); unscraped "
                    "(2, median) %.1f and (2c) %.1f tx/s\n",
                    scraped.rate, scraped.rate / limit.limit_tps, ratio(scraped.rate, floor.tps),
                    scraped.figures.p99_us / 1000.0, static_cast<unsigned long long>(scraped.figures.errors),
                    first_rate, again.rate);
        std::printf("summary: scraping cost: line rate %+.2f%% against the unscraped mean; unscraped runs differ by "
                    "%.2f%%\n",
                    100.0 * (scraped.rate - mean) / mean, 100.0 * std::abs(first_rate - again.rate) / mean);
        std::printf("scrapes %llu ok, %llu failed%s%s; %zu bytes each; scrape latency p50 %.2f ms, max %.2f ms\n",
                    static_cast<unsigned long long>(scrapes.ok), static_cast<unsigned long long>(scrapes.failed),
                    scrapes.failure.empty() ? "" : ": ", scrapes.failure.c_str(), scrapes.last_bytes,
                    bench::percentile_of_sorted(scrapes.latency_us, 0.5) / 1000.0,
                    scrapes.latency_us.empty() ? 0.0 : scrapes.latency_us.back() / 1000.0);
        std::printf("daemon CPU per serial transaction: %.1f us scraped (%.2fx the floor), %.1f us (2c) unscraped "
                    "(%.2fx the floor)\n",
                    scraped.cpu_us, ratio(scraped.cpu_us, floor.cpu_us), again.cpu_us,
                    ratio(again.cpu_us, floor.cpu_us));
    }

    // ---- 3: a write's latency while 16 clients saturate the line ------------------
    if (options.has("write")) {
        const bench::WindowFigures floor = floor_window();
        std::atomic<bool> stop_readers{false};
        std::vector<ClientResult> readers(16);
        std::vector<std::thread> reader_threads;
        const auto never = Clock::time_point::max();  // the readers' latencies are not wanted here
        for (std::size_t i = 0; i < readers.size(); ++i) {
            reader_threads.emplace_back(run_client, port, direct_target, std::uint64_t{i} * 7, std::cref(stop_readers),
                                        never, never, std::ref(readers[i]));
        }
        std::this_thread::sleep_for(milliseconds{500});
        const auto c_requests0 = bus_counter(sim, "line-b", "requests");
        const auto c0 = Clock::now();
        bench::StallProbe probe;
        ClientResult writes = run_writer(port, 2, shape.write_register(), options.writes);
        const bench::StallFigures stall = probe.stop();
        const double c_seconds = duration<double>(Clock::now() - c0).count();
        const auto c_requests = bus_counter(sim, "line-b", "requests") - c_requests0;
        stop_readers = true;
        for (auto& thread : reader_threads) thread.join();
        std::uint64_t reader_errors = 0;
        for (const auto& reader : readers) reader_errors += reader.errors + (reader.failure.empty() ? 0 : 1);
        const bench::Spread write_latency = bench::spread_of(writes.latency_us);
        const double w_p50 = write_latency.p50 / 1000.0;
        const double w_p99 = write_latency.p99 / 1000.0;
        const double w_max = write_latency.max / 1000.0;
        const double line_rate = static_cast<double>(c_requests) / c_seconds;
        std::printf("== fb_bench_tcp_daemon (3) write latency: 16 clients reading, one writing FC06 every 30-50 ms, "
                    "%s ==\n",
                    label.c_str());
        std::printf("T_write (%zu + %zu bytes on the line) = %.3f ms; priority ideal p50 = %.3f ms, max = %.3f ms\n",
                    shape.write_request_bytes(), shape.write_reply_bytes(), limit.t_write_ms,
                    limit.write_ideal_p50_ms(), limit.write_ideal_max_ms());
        std::printf("%zu writes ok, %llu failed%s%s; line-b meanwhile %.1f requests/s (%.3f of the limit, %.3f of "
                    "the floor window just before (3): %.1f tx/s); reader errors %llu\n",
                    writes.latency_us.size(), static_cast<unsigned long long>(writes.errors),
                    writes.failure.empty() ? "" : "; writer stopped: ", writes.failure.c_str(), line_rate,
                    line_rate / limit.limit_tps, ratio(line_rate, floor.tps), floor.tps,
                    static_cast<unsigned long long>(reader_errors));
        std::printf("write latency p50 %.3f ms, p99 %.3f ms, max %.3f ms\n", w_p50, w_p99, w_max);
        bench::print_stall("fb_bench_tcp_daemon", stall, w_max - limit.write_ideal_max_ms());
        std::printf("summary: TCP write %s under 16 readers: p50 %.3f ms = %.2fx the priority ideal (target <= 1.1), "
                    "max %.3f ms = %.2fx (target <= 1.3); machine stall max %.3f ms\n",
                    label.c_str(), w_p50, w_p50 / limit.write_ideal_p50_ms(), w_max, w_max / limit.write_ideal_max_ms(),
                    stall.max_us / 1000.0);
    }
    std::printf("gap_violations: line-a %llu, line-b %llu (target 0); shortest silence on line-b %s us\n",
                static_cast<unsigned long long>(bus_counter(sim, "line-a", "gap_violations")),
                static_cast<unsigned long long>(bus_counter(sim, "line-b", "gap_violations")),
                sim.stats()["buses"]["line-b"].value("min_silence_us", nlohmann::json("?")).dump().c_str());
    daemon.print_warnings("at the end");

    const int daemon_status = daemon.terminate();
    if (daemon_status != 0) {
        std::fprintf(stderr, "fieldbridge exit status %d; log:\n%s\n", daemon_status, daemon.log_text().c_str());
    }
    sim.terminate();
    return 0;
}

std::vector<std::string> split(std::string_view text) {
    std::vector<std::string> items;
    std::size_t from = 0;
    while (from <= text.size()) {
        const std::size_t comma = std::min(text.find(',', from), text.size());
        if (comma > from) items.emplace_back(text.substr(from, comma - from));
        from = comma + 1;
    }
    return items;
}

Options parse(int argc, char** argv) {
    Options options;
    std::vector<std::string> positional;
    for (int i = 1; i < argc; ++i) {
        const std::string_view arg = argv[i];
        const auto value = [&](std::string_view key) -> std::optional<std::string_view> {
            if (arg.substr(0, key.size()) != key) return std::nullopt;
            return arg.substr(key.size());
        };
        if (const auto shape = value("--shape=")) {
            options.shape = LoadShape::parse(*shape);
        } else if (const auto baud = value("--baud=")) {
            options.baud = static_cast<std::uint32_t>(std::stoul(std::string(*baud)));
        } else if (const auto clients = value("--clients=")) {
            options.clients.clear();
            for (const auto& item : split(*clients)) options.clients.push_back(static_cast<unsigned>(std::stoul(item)));
        } else if (const auto parts = value("--parts=")) {
            options.parts = split(*parts);
        } else if (const auto runs = value("--paced-runs=")) {
            options.paced_runs = std::stoi(std::string(*runs));
        } else if (arg.substr(0, 2) == "--") {
            throw std::invalid_argument("unknown option " + std::string(arg));
        } else {
            positional.emplace_back(arg);
        }
    }
    if (positional.empty()) throw std::invalid_argument("the fieldbridge binary is missing");
    options.daemon = positional[0];
    if (positional.size() > 1) options.seconds = std::stod(positional[1]);
    if (positional.size() > 2) options.writes = std::stoi(positional[2]);
    for (const auto& part : options.parts) {
        if (part != "cache" && part != "line" && part != "scrape" && part != "write") {
            throw std::invalid_argument("unknown part " + part + "; use cache, line, scrape, write");
        }
    }
    if (options.seconds <= 0.0 || options.writes <= 0 || options.baud == 0 || options.clients.empty() ||
        options.paced_runs <= 0) {
        throw std::invalid_argument("seconds, writes, baud, clients and paced runs must be positive");
    }
    return options;
}

}  // namespace

int main(int argc, char** argv) {
    Options options;
    try {
        options = parse(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr,
                     "fb_bench_tcp_daemon: %s\nusage: fb_bench_tcp_daemon FIELDBRIDGE [seconds=5] [writes=200] "
                     "[--shape=xeg|generic] [--baud=115200] [--clients=16,...] [--parts=cache,line,scrape,write] "
                     "[--paced-runs=3]  (FIELDBRIDGE_SIM names the simulator)\n",
                     e.what());
        return 2;
    }
    try {
        return run(options);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "fb_bench_tcp_daemon: %s\n", e.what());
        return 1;
    }
}
