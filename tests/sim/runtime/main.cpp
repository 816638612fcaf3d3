// fieldbridge-sim: simulated RS-485 devices on pseudo-terminals and a Huacheng R6
// Modbus TCP simulator. main() is the list of duties: parse options, build the
// simulator, start it, say READY, run until a signal or --duration, exit cleanly.
#include <csignal>
#include <iostream>
#include <sys/prctl.h>

#include <CLI/CLI.hpp>
#include <asio/io_context.hpp>
#include <asio/signal_set.hpp>
#include <asio/steady_timer.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "sim_error.hpp"
#include "sim_options.hpp"
#include "simulator.hpp"

namespace {

namespace runtime = fieldbridge::sim::runtime;

int run(const runtime::SimOptions& options, const std::shared_ptr<spdlog::logger>& log) {
    asio::io_context io(1);
    runtime::Simulator simulator(io, options, log);
    asio::signal_set signals(io, SIGINT, SIGTERM);
    asio::steady_timer duration_timer(io);

    const auto stop = [&](std::string_view why) {
        log->info("stopping: {}", why);
        signals.cancel();
        duration_timer.cancel();
        simulator.shutdown();
        io.stop();
    };
    signals.async_wait([&](const asio::error_code& error, int signal_number) {
        if (!error) {
            stop(signal_number == SIGINT ? "SIGINT" : "SIGTERM");
        }
    });
    if (options.duration) {
        duration_timer.expires_after(*options.duration);
        duration_timer.async_wait([&](const asio::error_code& error) {
            if (!error) {
                stop("--duration elapsed");
            }
        });
    }

    simulator.start();
    std::cout << "READY" << std::endl;  // flushed: scripts wait for this line
    io.run();
    simulator.shutdown();
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app;
    runtime::RawOptions raw;
    runtime::add_options(app, raw);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    }

    auto log = std::make_shared<spdlog::logger>("fieldbridge-sim",
                                                std::make_shared<spdlog::sinks::stderr_color_sink_mt>());
    log->set_pattern("%Y-%m-%d %H:%M:%S.%e %^%l%$ %v");
    runtime::SimOptions options;
    try {
        options = runtime::build_options(raw);
    } catch (const runtime::SimError& e) {
        std::cerr << "fieldbridge-sim: " << e.what() << '\n';
        return 2;
    }
    log->set_level(spdlog::level::from_str(options.log_level));
    log->flush_on(spdlog::level::warn);

    // Replies are due at exact moments: ask the kernel for no timer slack (the
    // default 50 us would add up to 50 us to every emulated reply).
    ::prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
    // A client that vanishes mid-write must not kill the simulator.
    std::signal(SIGPIPE, SIG_IGN);

    try {
        return run(options, log);
    } catch (const runtime::SimError& e) {
        log->error("{}", e.what());
        return 1;
    } catch (const std::exception& e) {
        log->error("unexpected failure: {}", e.what());
        return 1;
    }
}
