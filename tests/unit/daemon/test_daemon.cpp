// The Daemon's start-up, readiness, reload and status duties, driven through a
// fake service manager.

#include <doctest/doctest.h>

#include <csignal>
#include <stdexcept>

#include "core/error.hpp"
#include "config/diagnostic.hpp"
#include "daemon/exit_codes.hpp"
#include "daemon/status_board.hpp"
#include "daemon_test_support.hpp"

using namespace fieldbridge::daemon;
using namespace fieldbridge::daemon::testing;
namespace config = fieldbridge::config;

TEST_CASE("without components: READY=1 right after start-up, no watchdog, exit 0 on stop") {
    Harness h;
    auto& daemon = h.create();
    h.manager.on_notify = [&](const std::string& message) {
        if (starts_with(message, "READY=1")) {
            CHECK(daemon.phase() == Daemon::Phase::running);
            h.later([&] { daemon.request_stop("SIGTERM received"); });
        }
    };
    CHECK(h.run() == exit_ok);
    CHECK(h.manager.messages == std::vector<std::string>{
                                    "STATUS=starting, 2 lines, 4 devices",
                                    "READY=1\nSTATUS=2 lines, 4 devices",
                                    "STOPPING=1\nSTATUS=stopping, 2 lines, 4 devices",
                                });
    CHECK(daemon.phase() == Daemon::Phase::stopped);
    CHECK(h.logged("<6>starting gateway 'test' with gw.yaml (2 lines, 4 devices, MQTT disabled)\n"));
    CHECK(h.logged("<6>ready: 2 lines, 4 devices\n"));
    CHECK(h.logged("<6>stopping: SIGTERM received\n"));
    CHECK(h.logged("<6>stopped\n"));
}

TEST_CASE("READY=1 waits for every component's readiness ticket") {
    Harness h;
    FakeComponent tcp("modbus-tcp", h.events);
    FakeComponent mqtt("mqtt", h.events);
    FakeComponent lines("lines", h.events);
    tcp.needs_ready_ticket = true;
    mqtt.needs_ready_ticket = true;
    auto& daemon = h.create();
    daemon.add_component(tcp);
    daemon.add_component(mqtt);
    daemon.add_component(lines);

    h.manager.on_notify = [&](const std::string& message) {
        if (starts_with(message, "STATUS=starting")) {
            // Everything started, both listeners still pending.
            CHECK(message == "STATUS=starting, waiting for modbus-tcp listener, mqtt listener, 2 lines, 4 devices");
            h.later([&] {
                CHECK(h.manager.count("READY=1") == 0);
                tcp.ready.done();
                h.later([&] {
                    CHECK(h.manager.count("READY=1") == 0);  // mqtt still pending
                    CHECK(daemon.phase() == Daemon::Phase::starting);
                    mqtt.ready.done();
                });
            });
        }
        if (starts_with(message, "READY=1")) {
            h.later([&] { daemon.request_stop("test"); });
        }
    };
    CHECK(h.run() == exit_ok);
    CHECK(h.manager.count("READY=1") == 1);
    CHECK(h.events == std::vector<std::string>{"start modbus-tcp", "start mqtt", "start lines", "stop lines",
                                               "stop mqtt", "stop modbus-tcp"});
    CHECK(tcp.started_with == h.initial);
}

TEST_CASE("a valid reload: RELOADING=1, components get the new configuration, READY=1 again") {
    Harness h;
    FakeComponent lines("lines", h.events);
    FakeComponent tcp("modbus-tcp", h.events);
    const std::shared_ptr<const config::Config> changed = config_with(3, 1);
    h.loader = [&](const std::filesystem::path& file) {
        CHECK(file == "gw.yaml");
        return changed;
    };
    auto& daemon = h.create();
    daemon.add_component(lines);
    daemon.add_component(tcp);
    int readies = 0;
    h.manager.on_notify = [&](const std::string& message) {
        if (starts_with(message, "READY=1")) {
            ++readies;
            h.later([&, first = readies == 1] {
                if (first) {
                    daemon.request_reload();
                } else {
                    daemon.request_stop("test");
                }
            });
        }
    };
    CHECK(h.run() == exit_ok);
    const auto messages = h.manager.without_pings();
    REQUIRE(messages.size() == 5);
    CHECK(messages[1] == "READY=1\nSTATUS=2 lines, 4 devices");
    CHECK(starts_with(messages[2], "RELOADING=1\nMONOTONIC_USEC="));
    CHECK(messages[2].size() > std::string("RELOADING=1\nMONOTONIC_USEC=").size());
    CHECK(messages[3] == "READY=1\nSTATUS=3 lines, 3 devices");
    CHECK(h.loads == 1);
    CHECK(daemon.config() == changed);
    REQUIRE(lines.applied.size() == 1);
    CHECK(lines.applied[0] == changed);
    REQUIRE(tcp.applied.size() == 1);
    CHECK(h.events == std::vector<std::string>{"start lines", "start modbus-tcp", "apply lines", "apply modbus-tcp",
                                               "stop modbus-tcp", "stop lines"});
    CHECK(h.logged("<6>configuration reloaded from gw.yaml (3 lines, 3 devices, MQTT disabled); read and checked in "));
    // What the apply held the loop for, wall and CPU time, then each component in the
    // order they applied.
    const auto text = h.log_text.str();
    CHECK(text.find(" ms on the loop, ") != std::string::npos);
    const auto lines_at = text.find(" ms of CPU (lines ");
    REQUIRE(lines_at != std::string::npos);
    CHECK(text.find(" ms, modbus-tcp ", lines_at) != std::string::npos);
}

TEST_CASE("an invalid reload is rejected: every diagnostic logged, the old configuration stays") {
    Harness h;
    FakeComponent lines("lines", h.events);
    int attempt = 0;
    const std::shared_ptr<const config::Config> good = config_with(1, 1);
    h.loader = [&](const std::filesystem::path&) -> std::shared_ptr<const config::Config> {
        if (++attempt == 1) {
            throw config::ConfigError({config::Diagnostic{"gw.yaml", 4, 7, "lines[1].port", "must be absolute"},
                                       config::Diagnostic{"gw.yaml", 9, 3, "mqtt.qos", "expected 0, 1 or 2"}});
        }
        return good;
    };
    auto& daemon = h.create();
    daemon.add_component(lines);
    int readies = 0;
    h.manager.on_notify = [&](const std::string& message) {
        if (starts_with(message, "READY=1")) {
            ++readies;
            h.later([&, n = readies] {
                if (n == 2) {
                    // After the rejected reload: still running, nothing applied.
                    CHECK(daemon.phase() == Daemon::Phase::running);
                    CHECK(daemon.config() == h.initial);
                    CHECK(lines.applied.empty());
                }
                if (n <= 2) {
                    daemon.request_reload();
                } else {
                    daemon.request_stop("test");
                }
            });
        }
    };
    CHECK(h.run() == exit_ok);
    const auto messages = h.manager.without_pings();
    REQUIRE(messages.size() == 7);
    CHECK(starts_with(messages[2], "RELOADING=1\n"));
    CHECK(messages[3] == "READY=1\nSTATUS=last reload rejected (see the log), 2 lines, 4 devices");
    CHECK(starts_with(messages[4], "RELOADING=1\n"));
    CHECK(messages[5] == "READY=1\nSTATUS=1 line, 1 device");  // a good reload clears the note
    CHECK(h.logged("<3>gw.yaml:4:7: lines[1].port: must be absolute\n"));
    CHECK(h.logged("<3>gw.yaml:9:3: mqtt.qos: expected 0, 1 or 2\n"));
    CHECK(h.logged("<3>configuration reload rejected: 2 problems in gw.yaml;"));
    CHECK(lines.applied.size() == 1);
    CHECK(daemon.config() == good);
}

TEST_CASE("a loader failing for another reason is also survived") {
    Harness h;
    h.loader = [](const std::filesystem::path&) -> std::shared_ptr<const config::Config> {
        throw std::runtime_error("out of memory");
    };
    auto& daemon = h.create();
    int readies = 0;
    h.manager.on_notify = [&](const std::string& message) {
        if (starts_with(message, "READY=1") && ++readies <= 2) {
            h.later([&, n = readies] { n == 1 ? daemon.request_reload() : daemon.request_stop("test"); });
        }
    };
    CHECK(h.run() == exit_ok);
    CHECK(h.logged("<3>configuration reload failed: gw.yaml: out of memory;"));
    CHECK(daemon.config() == h.initial);
}

TEST_CASE("a component refusing to prepare a reload rejects it whole: nothing applied, the reason in STATUS=") {
    Harness h;
    FakeComponent lines("lines", h.events);
    FakeComponent tcp("modbus-tcp", h.events);
    FakeComponent mqtt("mqtt", h.events);
    tcp.refuses_prepare = "cannot listen on 127.0.0.1:1502: Address already in use; free the port or change it";
    h.loader = [&](const std::filesystem::path&) { return config_with(3, 1); };
    auto& daemon = h.create();
    daemon.add_component(lines);
    daemon.add_component(tcp);
    daemon.add_component(mqtt);
    int readies = 0;
    h.manager.on_notify = [&](const std::string& message) {
        if (starts_with(message, "READY=1")) {
            ++readies;
            h.later([&, n = readies] { n == 1 ? daemon.request_reload() : daemon.request_stop("test"); });
        }
    };
    CHECK(h.run() == exit_ok);
    const auto messages = h.manager.without_pings();
    REQUIRE(messages.size() >= 4);
    CHECK(messages[3] == "READY=1\nSTATUS=last reload rejected: cannot listen on 127.0.0.1:1502: "
                         "Address already in use; free the port or change it, 2 lines, 4 devices");
    CHECK(daemon.config() == h.initial);
    CHECK(lines.applied.empty());
    CHECK(tcp.applied.empty());
    CHECK(mqtt.applied.empty());
    // Only the component prepared before the refusal releases what it took.
    CHECK(h.events == std::vector<std::string>{"start lines", "start modbus-tcp", "start mqtt", "abandon lines",
                                               "stop mqtt", "stop modbus-tcp", "stop lines"});
    CHECK(h.logged("<3>configuration reload rejected: modbus-tcp cannot apply it: cannot listen on 127.0.0.1:1502"));
}

TEST_CASE("a component failing to apply a reload is logged; the others still get it") {
    class Refusing final : public Component {
    public:
        [[nodiscard]] std::string name() const override { return "mqtt"; }
        void start(StartContext&) override {}
        void stop(StopContext&) override {}
        void apply(std::shared_ptr<const config::Config>) override { throw std::runtime_error("broker URI changed"); }
    };
    Harness h;
    Refusing refusing;
    FakeComponent lines("lines", h.events);
    auto& daemon = h.create();
    daemon.add_component(refusing);
    daemon.add_component(lines);
    int readies = 0;
    h.manager.on_notify = [&](const std::string& message) {
        if (starts_with(message, "READY=1") && ++readies <= 2) {
            h.later([&, n = readies] { n == 1 ? daemon.request_reload() : daemon.request_stop("test"); });
        }
    };
    CHECK(h.run() == exit_ok);
    CHECK(h.logged("<3>mqtt could not apply the new configuration: broker URI changed;"));
    CHECK(lines.applied.size() == 1);
}

TEST_CASE("SIGHUP during start-up is deferred until READY") {
    Harness h;
    FakeComponent tcp("modbus-tcp", h.events);
    tcp.needs_ready_ticket = true;
    auto& daemon = h.create();
    daemon.add_component(tcp);
    int readies = 0;
    h.manager.on_notify = [&](const std::string& message) {
        if (starts_with(message, "STATUS=starting")) {
            h.later([&] {
                daemon.request_reload();
                CHECK(h.loads == 0);
                tcp.ready.done();
            });
        }
        if (starts_with(message, "READY=1") && ++readies == 2) {
            h.later([&] { daemon.request_stop("test"); });
        }
    };
    CHECK(h.run() == exit_ok);
    const auto messages = h.manager.without_pings();
    REQUIRE(messages.size() == 5);
    CHECK(starts_with(messages[1], "READY=1\n"));
    CHECK(starts_with(messages[2], "RELOADING=1\n"));
    CHECK(starts_with(messages[3], "READY=1\n"));
    CHECK(h.loads == 1);
    CHECK(h.logged("<6>reload requested during start-up"));
}

TEST_CASE("the log level: from the configuration, also after reload, unless overridden") {
    SUBCASE("configured level follows reloads") {
        Harness h;
        auto quiet = config_with(1, 1);
        quiet->gateway.log_level = config::LogLevel::warning;
        h.initial = quiet;
        auto verbose = config_with(1, 1);
        verbose->gateway.log_level = config::LogLevel::debug;
        h.loader = [&](const std::filesystem::path&) { return verbose; };
        auto& daemon = h.create();
        int readies = 0;
        h.manager.on_notify = [&](const std::string& message) {
            if (starts_with(message, "READY=1") && ++readies <= 2) {
                h.later([&, n = readies] {
                    if (n == 1) {
                        CHECK(h.logger->level() == spdlog::level::warn);
                        daemon.request_reload();
                    } else {
                        CHECK(h.logger->level() == spdlog::level::debug);
                        daemon.request_stop("test");
                    }
                });
            }
        };
        CHECK(h.run() == exit_ok);
        CHECK_FALSE(h.logged("ready: "));  // info, below warning at that time
        CHECK(h.logged("<6>log level: debug\n"));
    }
    SUBCASE("--log-level wins") {
        Harness h;
        h.options.log_level_override = config::LogLevel::error;
        auto verbose = config_with(1, 1);
        verbose->gateway.log_level = config::LogLevel::trace;
        h.loader = [&](const std::filesystem::path&) { return verbose; };
        auto& daemon = h.create();
        int readies = 0;
        h.manager.on_notify = [&](const std::string& message) {
            if (starts_with(message, "READY=1") && ++readies <= 2) {
                h.later([&, n = readies] { n == 1 ? daemon.request_reload() : daemon.request_stop("test"); });
            }
        };
        CHECK(h.run() == exit_ok);
        CHECK(h.logger->level() == spdlog::level::err);
        CHECK(h.log_text.str().empty());
    }
}

TEST_CASE("the watchdog is pinged from the loop at half the timeout") {
    Harness h;
    h.manager.watchdog = std::chrono::milliseconds{20};
    auto& daemon = h.create();
    const auto started = std::chrono::steady_clock::now();
    h.manager.on_notify = [&](const std::string& message) {
        if (message == "WATCHDOG=1" && h.manager.count("WATCHDOG=1") == 4) {
            h.later([&] { daemon.request_stop("test"); });
        }
    };
    CHECK(h.run() == exit_ok);
    const auto elapsed = std::chrono::steady_clock::now() - started;
    CHECK(h.manager.messages.front() == "WATCHDOG=1");  // the first ping at start-up
    CHECK(h.manager.count("WATCHDOG=1") >= 4);
    // Pings 2..4 come one period (10 ms) apart, none early.
    CHECK(elapsed >= std::chrono::milliseconds{30});
    CHECK(h.logged("<6>systemd watchdog enabled: pinging every 10 ms\n"));
}

TEST_CASE("STATUS= is refreshed periodically, and only when it changed") {
    Harness h;
    h.options.status_period = std::chrono::milliseconds{5};
    auto& daemon = h.create();
    std::size_t clients = 0;
    daemon.add_status([&] { return count_of(clients, "TCP client", "TCP clients"); });
    asio::steady_timer settle(daemon.context());
    h.manager.on_notify = [&](const std::string& message) {
        if (starts_with(message, "READY=1")) {
            CHECK(message == "READY=1\nSTATUS=2 lines, 4 devices, 0 TCP clients");
            h.later([&] { clients = 3; });
        }
        if (message == "STATUS=2 lines, 4 devices, 3 TCP clients") {
            // Let several more periods pass: nothing changed, nothing is sent.
            settle.expires_after(std::chrono::milliseconds{40});
            settle.async_wait([&](const std::error_code& error) {
                if (!error) {
                    daemon.request_stop("test");
                }
            });
        }
    };
    CHECK(h.run() == exit_ok);
    CHECK(h.manager.count("STATUS=2 lines, 4 devices, 3 TCP clients") == 1);
    CHECK(h.manager.count("STATUS=") == 2);  // "starting" and the change; READY carries its own
}

TEST_CASE("signals arrive through the loop: SIGHUP reloads, SIGTERM stops") {
    Harness h;
    h.create();
    int readies = 0;
    h.manager.on_notify = [&](const std::string& message) {
        if (starts_with(message, "READY=1")) {
            ++readies;
            // raise() delivers synchronously to this thread; asio's handler only
            // records it, and the daemon acts on its next loop turn.
            h.later([n = readies] { std::raise(n == 1 ? SIGHUP : SIGTERM); });
        }
    };
    CHECK(h.run() == exit_ok);
    CHECK(h.manager.count("RELOADING=1") == 1);
    CHECK(h.manager.count("STOPPING=1") == 1);
    CHECK(h.loads == 1);
    CHECK(h.logged("<6>SIGHUP received: reloading the configuration\n"));
    CHECK(h.logged("<6>stopping: SIGTERM received\n"));
}

TEST_CASE("misuse is reported") {
    Harness h;
    CHECK_THROWS_AS(Daemon(h.options, nullptr, h.loader, h.manager, h.logger), fieldbridge::core::InvalidArgument);
    auto& daemon = h.create();
    h.manager.on_notify = [&](const std::string& message) {
        if (starts_with(message, "READY=1")) {
            h.later([&] { daemon.request_stop("test"); });
        }
    };
    CHECK(h.run() == exit_ok);
    FakeComponent late("late", h.events);
    CHECK_THROWS_AS(daemon.add_component(late), std::logic_error);
    CHECK_THROWS_AS(static_cast<void>(daemon.run()), std::logic_error);
}
