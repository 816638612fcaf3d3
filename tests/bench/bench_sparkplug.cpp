// Benchmark of the Sparkplug B edge node (issue 28): what publishing costs per changed
// point, and whether it moves a line's rate or a write's latency, with 64 devices x 50
// points changing every second.
//
//   FIELDBRIDGE_SIM=<fieldbridge-sim> fb_bench_sparkplug <fieldbridge> [seconds=10] [writes=200]
//       [--baud=115200] [--pairs=3] [--keep]
//
// The set-up, on loopback:
//   - a mosquitto of its own on a free port (as fb_bench_footprint starts one);
//   - fieldbridge-sim --wire-time (1 ms turnaround) with 4 polled lines, line-a..line-d,
//     of 16 devices each (bus addresses 1-16): the simulator's device is a definition
//     written here, `bench50` (50 uint16 holding registers 0-49), so that its registers
//     can be set through the control socket (`set-register`); and line-e, the
//     `generic` load shape's 4 generic `modbus` devices (load_shape.hpp), for the line
//     rate and the write latency;
//   - the daemon: every polled device a generic `modbus` device with 50 inline uint16
//     holding points p00..p49 polled every 500 ms (one FC03 of 50 registers), line-e's
//     devices as in fb_bench_tcp_daemon (max_age 0, every read to the line), `mqtt:`
//     on (the JSON bridge) in every run, and `sparkplug:` (group `bench`, state_dir a
//     temporary directory) in the "on" runs only;
//   - a changer thread of this process: every second, for each of the 64 devices, one
//     `device line-X@A set-register holding 0 v0 ... v49` with v_i = (round + 1000 i +
//     7 d) mod 65536 (d the device's index 0-63): every point changes every second,
//     and a value says which round and point it came from;
//   - a subscriber: `mosquitto_sub -t 'spBv1.0/#' -F '%t %x'` to a file for the whole
//     run, decoded at the end by the tests' own decoder (tests/support/sparkplug_decode.py
//     --lines, independent of the gateway's encoder).
//
// Runs: `--pairs` pairs of daemon runs, Sparkplug off and on (the order alternates
// pair by pair: off-on, on-off, ...), the same simulator, broker and changer. In each:
// the daemon started, "ready", MQTT connected (and Sparkplug connected), 3 s of
// warm-up, then
//   P. publishing: `seconds` with line-e idle: the daemon's CPU time (process CPU
//      clock) per second, the polled lines' requests (simulator counters);
//   P0. nothing changing: the changer paused (1.5 s after its last round), `seconds`:
//      the daemon's CPU time per second again (what Sparkplug costs without changes:
//      the node's one-second sweep, node metrics); the changes resume 1.5 s before L;
//   L. line rate: 16 blocking clients (nice 10) read line-e flat out for `seconds`
//      (tcp_load.hpp): line-e's requests per second from the simulator's counter;
//   W. write latency: the 16 readers go on while a 17th client writes FC06 every
//      30-50 ms, `writes` times (part (3) of fb_bench_tcp_daemon): p50, p99, max.
// Figures: per pair the ratio on/off of each; the cost per changed point published =
// (CPU/s on - CPU/s off) / (DDATA metrics/s the subscriber saw in the on run's window
// P, by the payloads' timestamps), and the same with P0's on - off taken away first.
// Cross-check: for every round of the changer that falls in a window P, every one of
// its 3,200 (device, point) values must appear in exactly one DDATA metric (alias ->
// point from the run's DBIRTHs, value -> round).
// Not a test: it prints figures and asserts nothing. The cell and its changer are in
// sparkplug_cell.hpp, the reading of the subscriber's decoded messages in
// sparkplug_seen.hpp.

#include <stdlib.h>  // mkdtemp

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "broker_support.hpp"
#include "child_process.hpp"
#include "daemon_process.hpp"
#include "line_limit.hpp"
#include "load_shape.hpp"
#include "loopback_port.hpp"
#include "percentile.hpp"
#include "sim_process.hpp"
#include "sparkplug_cell.hpp"
#include "sparkplug_seen.hpp"
#include "stall_probe.hpp"
#include "tcp_load.hpp"

#ifndef FB_SOURCE_DIR
#define FB_SOURCE_DIR "."
#endif

namespace {

using namespace fieldbridge;
using namespace fieldbridge::bench::sparkplug_cell;
using Clock = std::chrono::steady_clock;
using std::chrono::duration;
using std::chrono::milliseconds;

struct Options {
    std::string daemon;
    double seconds = 10.0;
    int writes = 200;
    std::uint32_t baud = 115200;
    int pairs = 3;
    bool keep = false;
};

/// What one daemon run measured.
struct RunFigures {
    bool sparkplug = false;
    int pair = 0;
    std::int64_t p_start_ms = 0;  ///< window P, UTC
    std::int64_t p_end_ms = 0;
    double p_seconds = 0.0;
    double cpu_per_s = 0.0;      ///< daemon CPU seconds per second in P
    double still_cpu_per_s = 0.0;  ///< the same in P0, nothing changing
    double broker_cpu_per_s = 0.0;
    double polled_requests_per_s = 0.0;
    double line_rate = 0.0;      ///< line-e requests/s in L (simulator)
    double answered_rate = 0.0;  ///< reads/s the clients got in L
    double read_p99_ms = 0.0;
    std::uint64_t read_errors = 0;
    double write_line_rate = 0.0;  ///< line-e requests/s during W
    bench::Spread write{};
    std::uint64_t write_errors = 0;
    bench::StallFigures stall{};
    double cpu_l_per_s = 0.0;  ///< daemon CPU per second in L
    std::string warnings;
};

RunFigures run_daemon(const Options& options, bool sparkplug, int pair, const test::SimProcess& sim, Changer& changer,
                      const std::string& broker_uri, const std::filesystem::path& work, const bench::LoadShape& shape,
                      const bench::LineLimit& limit) {
    RunFigures figures;
    figures.sparkplug = sparkplug;
    figures.pair = pair;
    const std::uint16_t port = bench::free_loopback_port();
    const std::string tag = fmt::format("pair{}-{}", pair, sparkplug ? "on" : "off");
    const auto config = work / (tag + ".yaml");
    std::ofstream(config) << daemon_yaml(options.baud, sparkplug, port, broker_uri, (work / "state").string(), sim,
                                         shape);
    bench::DaemonProcess daemon(options.daemon, config, work / (tag + ".log"));
    const bool mqtt = daemon.wait_for_log("MQTT: connected", std::chrono::seconds{10});
    const bool spb = !sparkplug || daemon.wait_for_log("Sparkplug: connected", std::chrono::seconds{10});
    std::this_thread::sleep_for(std::chrono::seconds{3});  // births, every device's first reads, steady polls
    const pid_t broker = bench::child_named("mosquitto");

    const auto polled = [&] {
        std::uint64_t requests = 0;
        for (int line = 0; line < polled_lines; ++line) requests += sim.bus_counter(polled_line(line), "requests");
        return requests;
    };
    // ---- P: publishing, line-e idle ----
    const auto p_requests0 = polled();
    const double cpu0 = daemon.cpu_seconds();
    const double broker0 = broker > 0 ? bench::process_cpu_seconds(broker) : 0.0;
    const auto t0 = Clock::now();
    figures.p_start_ms = utc_ms();
    std::this_thread::sleep_for(duration<double>(options.seconds));
    figures.p_end_ms = utc_ms();
    figures.p_seconds = duration<double>(Clock::now() - t0).count();
    figures.cpu_per_s = (daemon.cpu_seconds() - cpu0) / figures.p_seconds;
    figures.broker_cpu_per_s = broker > 0 ? (bench::process_cpu_seconds(broker) - broker0) / figures.p_seconds : 0.0;
    figures.polled_requests_per_s = static_cast<double>(polled() - p_requests0) / figures.p_seconds;

    // ---- P0: the same with nothing changing (what Sparkplug costs without changes) ----
    changer.pause(true);
    std::this_thread::sleep_for(milliseconds{1500});  // the last round read and published
    const double still0 = daemon.cpu_seconds();
    const auto s0 = Clock::now();
    std::this_thread::sleep_for(duration<double>(options.seconds));
    figures.still_cpu_per_s = (daemon.cpu_seconds() - still0) / duration<double>(Clock::now() - s0).count();
    changer.pause(false);
    std::this_thread::sleep_for(milliseconds{1500});  // changing again

    // ---- L: line-e flat out ----
    const bench::Target target{shape, line_e_first_unit};
    std::uint64_t e0 = 0;
    std::uint64_t e1 = 0;
    double lcpu0 = 0.0;
    double lcpu1 = 0.0;
    const bench::LoadFigures load = bench::run_load(port, target, 16, options.seconds, [&](bool start) {
        (start ? e0 : e1) = sim.bus_counter("line-e", "requests");
        (start ? lcpu0 : lcpu1) = daemon.cpu_seconds();
    });
    figures.line_rate = static_cast<double>(e1 - e0) / load.seconds;
    figures.answered_rate = static_cast<double>(load.reads) / load.seconds;
    figures.read_p99_ms = load.p99_us / 1000.0;
    figures.read_errors = load.errors + (load.failures.empty() ? 0 : 1);
    figures.cpu_l_per_s = (lcpu1 - lcpu0) / load.seconds;

    // ---- W: a write's latency under the same readers ----
    {
        std::atomic<bool> stop_readers{false};
        std::vector<bench::ClientResult> readers(16);
        std::vector<std::thread> threads;
        const auto never = Clock::time_point::max();
        for (std::size_t i = 0; i < readers.size(); ++i) {
            threads.emplace_back(bench::run_client, port, target, std::uint64_t{i} * 7, std::cref(stop_readers), never,
                                 never, std::ref(readers[i]));
        }
        std::this_thread::sleep_for(milliseconds{500});
        const auto w_requests0 = sim.bus_counter("line-e", "requests");
        const auto w0 = Clock::now();
        bench::StallProbe probe;
        const bench::ClientResult writes = bench::run_writer(port, line_e_first_unit, shape.write_register(), options.writes);
        figures.stall = probe.stop();
        const double w_seconds = duration<double>(Clock::now() - w0).count();
        figures.write_line_rate = static_cast<double>(sim.bus_counter("line-e", "requests") - w_requests0) / w_seconds;
        stop_readers = true;
        for (auto& thread : threads) thread.join();
        figures.write = bench::spread_of(writes.latency_us);
        figures.write_errors = writes.errors + (writes.failure.empty() ? 0 : 1);
    }
    std::printf("run pair %d, Sparkplug %-3s: MQTT %s%s; P: daemon CPU %.2f%% of a core (P0, nothing changing: %.2f%%), broker %.1f%%, polled lines "
                "%.1f requests/s; L: line-e %.1f requests/s (%.3f of the limit), clients %.1f reads/s, p99 %.2f ms, "
                "errors %llu, daemon CPU %.1f%%; W: %zu writes, p50 %.3f ms, p99 %.3f ms, max %.3f ms (ideal p50 "
                "%.3f, max %.3f), errors %llu, line-e %.1f requests/s, stall max %.2f ms\n",
                pair, sparkplug ? "on" : "off", mqtt ? "connected" : "NOT connected",
                sparkplug ? (spb ? ", Sparkplug connected" : ", Sparkplug NOT connected") : "",
                100.0 * figures.cpu_per_s, 100.0 * figures.still_cpu_per_s, 100.0 * figures.broker_cpu_per_s, figures.polled_requests_per_s,
                figures.line_rate, figures.line_rate / limit.limit_tps, figures.answered_rate, figures.read_p99_ms,
                static_cast<unsigned long long>(figures.read_errors), 100.0 * figures.cpu_l_per_s, figures.write.count,
                figures.write.p50 / 1000.0, figures.write.p99 / 1000.0, figures.write.max / 1000.0,
                limit.write_ideal_p50_ms(), limit.write_ideal_max_ms(),
                static_cast<unsigned long long>(figures.write_errors), figures.write_line_rate,
                figures.stall.max_us / 1000.0);
    daemon.print_warnings(tag);
    const int status = daemon.terminate();
    if (status != 0) std::printf("daemon %s exit status %d\n", tag.c_str(), status);
    std::fflush(stdout);
    return figures;
}

double ratio(double a, double b) { return b != 0.0 ? a / b : 0.0; }

int run(const Options& options) {
    const bench::LoadShape shape(bench::LoadShape::Kind::generic);
    const bench::LineLimit limit = bench::line_limit(shape, options.baud, turnaround);
    std::string work_template = "/tmp/fb-spb-bench-" + std::string(6, 'X');  // mkdtemp's template
    if (mkdtemp(work_template.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    const std::filesystem::path work = work_template;
    std::filesystem::create_directories(work / "state");
    std::ofstream(work / "bench50.yaml") << definition_yaml();

    // A read of 50 registers: 8 + 105 bytes, two t3.5 silences and the turnaround.
    const double char_ms = 10.0 * 1000.0 / options.baud;
    const double t_poll_ms = (8 + 5 + 2 * points + 7) * char_ms + 1.0;
    const double utilisation = devices_per_line * 2 * t_poll_ms / 1000.0;
    std::printf("fb_bench_sparkplug: %d polled lines x %d devices x %d uint16 points (one FC03 of %d registers a "
                "device every 500 ms: T_line %.2f ms, %.0f%% of each line at %u bit/s), every point changed every "
                "second through the simulator's control socket; line-e: %s, T_line %.3f ms -> limit %.1f tx/s\n",
                polled_lines, devices_per_line, points, points, t_poll_ms, 100.0 * utilisation, options.baud,
                std::string(shape.description()).c_str(), limit.t_read_ms, limit.limit_tps);
    std::printf("work directory %s%s\n", work.c_str(), options.keep ? " (kept)" : "");

    fbt::Mosquitto broker(fbt::free_port());
    broker.start();
    const std::string broker_uri = broker.uri();

    test::SimProcess sim(simulator_arguments(shape, options.baud, work / "bench50.yaml"));

    const auto raw = work / "spb.txt";
    bench::ChildProcess subscriber({"mosquitto_sub", "-h", "127.0.0.1", "-p", std::to_string(broker.port()), "-q", "1", "-t",
                      "spBv1.0/#", "-F", "%t %x"},
                     raw);
    std::this_thread::sleep_for(milliseconds{500});
    Changer changer(sim);

    std::vector<RunFigures> runs;
    for (int pair = 1; pair <= options.pairs; ++pair) {
        const bool on_first = pair % 2 == 0;
        for (const bool sparkplug : {on_first, !on_first}) {
            runs.push_back(run_daemon(options, sparkplug, pair, sim, changer, broker_uri, work, shape, limit));
        }
    }
    changer.stop();
    std::this_thread::sleep_for(milliseconds{500});
    subscriber.stop();
    const std::vector<Round> rounds = changer.rounds();
    int failed_commands = 0;
    for (const Round& r : rounds) failed_commands += r.failed;
    std::printf("changer: %zu rounds, %d of %zu commands failed%s%s\n", rounds.size(), failed_commands,
                rounds.size() * devices, changer.first_error().empty() ? "" : "; first: ",
                changer.first_error().c_str());

    // ---- the subscriber's count, decoded independently ----
    const auto decoded = work / "spb.jsonl";
    const std::string command = fmt::format("/usr/bin/python3 '{}/tests/support/sparkplug_decode.py' --lines < '{}' > '{}'",
                                            FB_SOURCE_DIR, raw.string(), decoded.string());
    const int rc = std::system(command.c_str());
    if (rc != 0) std::printf("the decoder failed (%d): %s\n", rc, command.c_str());
    const Seen seen = read_subscriber(decoded);
    std::string types;
    for (const auto& [type, count] : seen.by_type) types += fmt::format("{} {}, ", type, count);
    std::printf("subscriber (sparkplug_decode.py): %llu messages (%s%llu not decoded); line-e devices' DDATA metrics "
                "%llu; metrics without a DBIRTH alias %llu\n",
                static_cast<unsigned long long>(seen.messages), types.c_str(),
                static_cast<unsigned long long>(seen.decode_errors),
                static_cast<unsigned long long>(seen.other_ddata_metrics),
                static_cast<unsigned long long>(seen.unmapped_metrics));

    // Per on-run: the DDATA seen in window P, and the rounds of P against what was published.
    std::map<int, RunFigures> off_of;
    std::map<int, RunFigures> on_of;
    for (const RunFigures& r : runs) (r.sparkplug ? on_of : off_of)[r.pair] = r;
    std::vector<double> cost_us;
    std::vector<double> marginal_us;
    std::vector<double> still_delta;
    std::vector<double> cpu_ratio;
    std::vector<double> rate_ratio;
    std::vector<double> w50_ratio;
    std::vector<double> w99_ratio;
    std::vector<double> wmax_ratio;
    std::vector<double> points_per_s;
    std::uint64_t total_expected = 0;
    std::uint64_t total_found = 0;
    std::uint64_t total_missing = 0;
    std::uint64_t total_duplicates = 0;
    for (const auto& [pair, on] : on_of) {
        const auto off_it = off_of.find(pair);
        if (off_it == off_of.end()) continue;
        const RunFigures& off = off_it->second;
        std::uint64_t messages = 0;
        std::uint64_t metrics = 0;
        for (const auto& [timestamp, count] : seen.ddata) {
            if (timestamp >= on.p_start_ms && timestamp < on.p_end_ms) {
                ++messages;
                metrics += count;
            }
        }
        std::uint64_t expected = 0;
        std::uint64_t found = 0;
        std::uint64_t duplicates = 0;
        std::uint64_t in_window = 0;
        for (const Round& r : rounds) {
            if (r.end_ms < on.p_start_ms || r.end_ms >= on.p_end_ms || r.failed != 0) continue;
            ++in_window;
            for (int d = 0; d < devices; ++d) {
                for (int i = 0; i < points; ++i) {
                    ++expected;
                    const auto it = seen.published.find(change_key(r.number, d, i));
                    if (it == seen.published.end()) continue;
                    ++found;
                    duplicates += it->second - 1;
                }
            }
        }
        total_expected += expected;
        total_found += found;
        total_missing += expected - found;
        total_duplicates += duplicates;
        const double per_s = static_cast<double>(metrics) / on.p_seconds;
        points_per_s.push_back(per_s);
        const double cost = per_s > 0.0 ? (on.cpu_per_s - off.cpu_per_s) / per_s * 1e6 : 0.0;
        cost_us.push_back(cost);
        const double still = on.still_cpu_per_s - off.still_cpu_per_s;
        still_delta.push_back(still);
        const double marginal = per_s > 0.0 ? (on.cpu_per_s - off.cpu_per_s - still) / per_s * 1e6 : 0.0;
        marginal_us.push_back(marginal);
        cpu_ratio.push_back(ratio(on.cpu_per_s, off.cpu_per_s));
        rate_ratio.push_back(ratio(on.line_rate, off.line_rate));
        w50_ratio.push_back(ratio(on.write.p50, off.write.p50));
        w99_ratio.push_back(ratio(on.write.p99, off.write.p99));
        wmax_ratio.push_back(ratio(on.write.max, off.write.max));
        std::printf("pair %d: window P (on) %.1f s: subscriber DDATA %llu messages, %llu metrics = %.0f changed points "
                    "published/s; changer rounds in it %llu = %llu changes, of which published %llu (missing %llu, "
                    "duplicated %llu); daemon CPU %.2f%% on, %.2f%% off: %+.2f%% of a core = %.2f us per changed point "
                    "published; nothing changing (P0): %.2f%% on, %.2f%% off: %+.2f%% of a core, which leaves %.2f us per changed point; broker CPU %.1f%% on, %.1f%% off\n",
                    pair, on.p_seconds, static_cast<unsigned long long>(messages),
                    static_cast<unsigned long long>(metrics), per_s, static_cast<unsigned long long>(in_window),
                    static_cast<unsigned long long>(expected), static_cast<unsigned long long>(found),
                    static_cast<unsigned long long>(expected - found), static_cast<unsigned long long>(duplicates),
                    100.0 * on.cpu_per_s, 100.0 * off.cpu_per_s, 100.0 * (on.cpu_per_s - off.cpu_per_s), cost,
                    100.0 * on.still_cpu_per_s, 100.0 * off.still_cpu_per_s, 100.0 * still, marginal,
                    100.0 * on.broker_cpu_per_s, 100.0 * off.broker_cpu_per_s);
        std::printf("pair %d: line-e rate on/off %.1f / %.1f tx/s = %.3f; write p50 %.3f / %.3f ms = %.3f, p99 %.3f / "
                    "%.3f ms = %.3f, max %.3f / %.3f ms = %.3f; polled lines %.1f / %.1f requests/s\n",
                    pair, on.line_rate, off.line_rate, rate_ratio.back(), on.write.p50 / 1000.0,
                    off.write.p50 / 1000.0, w50_ratio.back(), on.write.p99 / 1000.0, off.write.p99 / 1000.0,
                    w99_ratio.back(), on.write.max / 1000.0, off.write.max / 1000.0, wmax_ratio.back(),
                    on.polled_requests_per_s, off.polled_requests_per_s);
    }
    std::printf("summary: Sparkplug publishing cost, %d devices x %d points changing every second, %u bit/s: "
                "%.2f us of daemon CPU per changed point published (median of %zu pairs, on - off); daemon CPU on/off "
                "%.3f; %.0f changed points published/s\n",
                devices, points, options.baud, bench::median_of(cost_us), cost_us.size(), bench::median_of(cpu_ratio),
                bench::median_of(points_per_s));
    std::printf("summary: Sparkplug with nothing changing (P0): %+.2f%% of a core on - off (median); per changed point "
                "beyond that: %.2f us (median of the pairs)\n",
                100.0 * bench::median_of(still_delta), bench::median_of(marginal_us));
    std::printf("summary: cross-check: %llu changes made in the on windows, %llu published in a DDATA (missing %llu, "
                "duplicated %llu)\n",
                static_cast<unsigned long long>(total_expected), static_cast<unsigned long long>(total_found),
                static_cast<unsigned long long>(total_missing), static_cast<unsigned long long>(total_duplicates));
    std::printf("summary: line-e (16 clients, generic, %u bit/s) rate on/off %.3f (median of the pairs); write "
                "latency on/off p50 %.3f, p99 %.3f, max %.3f\n",
                options.baud, bench::median_of(rate_ratio), bench::median_of(w50_ratio), bench::median_of(w99_ratio),
                bench::median_of(wmax_ratio));
    std::printf("gap_violations:");
    for (int line = 0; line < polled_lines; ++line) {
        std::printf(" %s %llu,", polled_line(line).c_str(),
                    static_cast<unsigned long long>(sim.bus_counter(polled_line(line), "gap_violations")));
    }
    std::printf(" line-e %llu (target 0)\n", static_cast<unsigned long long>(sim.bus_counter("line-e", "gap_violations")));
    sim.terminate();
    broker.stop();
    if (!options.keep) {
        std::error_code ignored;
        std::filesystem::remove_all(work, ignored);
    }
    return 0;
}

Options parse(int argc, char** argv) {
    Options options;
    std::vector<std::string> positional;
    for (int i = 1; i < argc; ++i) {
        const std::string_view arg = argv[i];
        if (arg.rfind("--baud=", 0) == 0) {
            options.baud = static_cast<std::uint32_t>(std::stoul(std::string(arg.substr(7))));
        } else if (arg.rfind("--pairs=", 0) == 0) {
            options.pairs = std::stoi(std::string(arg.substr(8)));
        } else if (arg == "--keep") {
            options.keep = true;
        } else if (arg.rfind("--", 0) == 0) {
            throw std::invalid_argument("unknown option " + std::string(arg));
        } else {
            positional.emplace_back(arg);
        }
    }
    if (positional.empty()) throw std::invalid_argument("the fieldbridge binary is missing");
    options.daemon = positional[0];
    if (positional.size() > 1) options.seconds = std::stod(positional[1]);
    if (positional.size() > 2) options.writes = std::stoi(positional[2]);
    if (options.seconds <= 0.0 || options.writes <= 0 || options.baud == 0 || options.pairs <= 0) {
        throw std::invalid_argument("seconds, writes, baud and pairs must be positive");
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
                     "fb_bench_sparkplug: %s\nusage: fb_bench_sparkplug FIELDBRIDGE [seconds=10] [writes=200] "
                     "[--baud=115200] [--pairs=3] [--keep]  (FIELDBRIDGE_SIM names the simulator)\n",
                     e.what());
        return 2;
    }
    try {
        return run(options);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "fb_bench_sparkplug: %s\n", e.what());
        return 1;
    }
}
