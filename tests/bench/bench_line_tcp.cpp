// Benchmark of a line behind a serial device server (issue 27): the real engine on
// `port: tcp://127.0.0.1:PORT`, where socat (a device server in transparent mode: TCP
// in, raw bytes to a tty) forwards to `fieldbridge-sim --wire-time` on a
// pseudo-terminal, against the same engine on a second pty of the same simulator
// directly. One HIWIN XEG on each bus, 1 ms device turnaround, 115200 bit/s or the
// baud given; 16 on-demand FC04 0x0300 x2 reads kept outstanding (max_age 0).
//
//   fb_bench_line_tcp [seconds=5] [baud=115200]
//
// The pty and the TCP line alternate in windows of `seconds` (three pairs); each
// pair's ratio tcp/pty of completed transactions per second is printed, and their
// median on a "summary:" line. The simulator binary is named by FIELDBRIDGE_SIM; socat
// must be on the PATH (deploy/install-deps.sh installs it). Not a test: it prints
// figures and asserts nothing.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "engine_harness.hpp"
#include "free_port.hpp"
#include "line_limit.hpp"
#include "load_shape.hpp"
#include "read_load.hpp"
#include "sim_process.hpp"

namespace {

using namespace fieldbridge;
using integration::EngineHarness;
using test::SimProcess;
using Clock = std::chrono::steady_clock;
using std::chrono::duration;
using std::chrono::milliseconds;
using std::chrono::seconds;

constexpr unsigned outstanding_reads = 16;
constexpr std::uint16_t status_address = 0x0300;

/// socat as a device server in "TCP server" mode in front of @p tty; killed by PID.
class Socat {
public:
    Socat(std::uint16_t port, const std::string& tty) {
        const std::string listen = fmt::format("TCP-LISTEN:{},bind=127.0.0.1,reuseaddr,nodelay", port);
        const std::string line = fmt::format("FILE:{},raw,echo=0", tty);
        pid_ = ::fork();
        if (pid_ == 0) {
            ::execlp("socat", "socat", listen.c_str(), line.c_str(), static_cast<char*>(nullptr));
            ::_exit(127);
        }
    }
    ~Socat() {
        if (pid_ <= 0) return;
        ::kill(pid_, SIGTERM);
        ::waitpid(pid_, nullptr, 0);
    }
    Socat(const Socat&) = delete;
    Socat& operator=(const Socat&) = delete;

private:
    pid_t pid_ = -1;
};

std::string engine_yaml(const std::string& pty, std::uint16_t tcp_port, std::uint32_t baud) {
    const auto line = [&](const char* name, const std::string& port, const char* extra, unsigned unit) {
        return fmt::format(R"(
  - name: {0}
    port: {1}
    baud: {2}{3}
    devices:
      - name: xeg-{0}
        type: hiwin-xeg
        address: 2
        unit_id: {4}
        max_age: 0ms
        queue_limit: 64
        command_ttl: 1s
        poll: {{ fast: 60min, slow: 60min, motion: 60min }})",
                           name, port, baud, extra, unit);
    };
    return "gateway: { id: bench-line-tcp }\nlines:" + line("pty", pty, "", 1) +
           line("tcp", fmt::format("tcp://127.0.0.1:{}", tcp_port),
                "\n    reconnect_backoff: { initial: 20ms, max: 100ms }", 2) +
           "\n";
}

/// Transactions per second of @p reads over one window of @p seconds.
double window_tps(EngineHarness& h, bench::ReadLoad& reads, double run_seconds) {
    reads.start(outstanding_reads);
    h.run_for(milliseconds{200});  // warm-up
    const std::uint64_t before = reads.completed();
    const auto t0 = Clock::now();
    h.run_for(std::chrono::duration_cast<engine::Duration>(duration<double>(run_seconds)));
    const double elapsed = duration<double>(Clock::now() - t0).count();
    const std::uint64_t done = reads.completed() - before;
    reads.stop();
    h.run_until([&] { return reads.in_flight() == 0; }, seconds{5});
    return static_cast<double>(done) / elapsed;
}

int run(double run_seconds, std::uint32_t baud) {
    const bench::LineLimit limit =
        bench::line_limit(bench::LoadShape(bench::LoadShape::Kind::xeg), baud, milliseconds{1});
    SimProcess sim({"--bus", "{dir}/line-pty:hiwin-xeg@2", "--bus", "{dir}/line-tcp:hiwin-xeg@2", "--wire-time",
                    "--baud", std::to_string(baud), "--turnaround", "1ms"});
    const std::uint16_t port = test::free_loopback_port();  // socat binds it right after
    Socat socat(port, sim.path("line-tcp"));
    EngineHarness h(engine_yaml(sim.path("line-pty"), port, baud));
    h.start();
    auto& on_pty = h.device("xeg-pty");
    auto& on_tcp = h.device("xeg-tcp");
    if (!h.run_until([&] { return on_pty.online() && on_tcp.online() && h.line("tcp").line_up(); }, seconds{10})) {
        std::fprintf(stderr, "fb_bench_line_tcp: the lines did not come up within 10 s\n%s\n", sim.log_text().c_str());
        return 1;
    }
    std::printf("== fb_bench_line_tcp: 16 reads outstanding, the pty line and the same line through a loopback "
                "device server (socat) in alternating %.1f s windows, %u bit/s (physical limit %.1f/s) ==\n",
                run_seconds, baud, limit.limit_tps);
    bench::ReadLoad pty_reads(on_pty, status_address);
    bench::ReadLoad tcp_reads(on_tcp, status_address);
    std::vector<double> ratios;
    for (int pair = 1; pair <= 3; ++pair) {
        const double pty = window_tps(h, pty_reads, run_seconds);
        const double tcp = window_tps(h, tcp_reads, run_seconds);
        ratios.push_back(tcp / pty);
        std::printf("pair %d: pty %.1f/s (%.3f of the limit), tcp %.1f/s (%.3f), tcp/pty %.3f\n", pair, pty,
                    pty / limit.limit_tps, tcp, tcp / limit.limit_tps, tcp / pty);
    }
    std::sort(ratios.begin(), ratios.end());
    std::printf("failed reads: pty %llu, tcp %llu\n", static_cast<unsigned long long>(pty_reads.failed()),
                static_cast<unsigned long long>(tcp_reads.failed()));
    std::printf("summary: line over a device server (TCP) / the same line on a pty at %u bit/s: %.3f (median of 3)\n",
                baud, ratios[1]);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        const double run_seconds = argc > 1 ? std::atof(argv[1]) : 5.0;
        const auto baud = static_cast<std::uint32_t>(argc > 2 ? std::atol(argv[2]) : 115200);
        return run(run_seconds, baud);
    } catch (const std::exception& error) {
        std::fprintf(stderr, "fb_bench_line_tcp: %s\n", error.what());
        return 1;
    }
}
