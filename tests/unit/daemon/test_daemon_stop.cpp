// The Daemon's shutdown: stop order, stop tickets, the stop timeout, start-up
// failures and fatal errors.

#include <doctest/doctest.h>

#include <stdexcept>

#include "daemon/exit_codes.hpp"
#include "daemon_test_support.hpp"

using namespace fieldbridge::daemon;
using namespace fieldbridge::daemon::testing;

TEST_CASE("components stop in reverse order and the loop waits for their stop tickets") {
    Harness h;
    FakeComponent lines("lines", h.events);
    FakeComponent tcp("modbus-tcp", h.events);
    FakeComponent mqtt("mqtt", h.events);
    lines.needs_stop_ticket = true;
    mqtt.needs_stop_ticket = true;
    auto& daemon = h.create();
    daemon.add_component(lines);
    daemon.add_component(tcp);
    daemon.add_component(mqtt);
    h.manager.on_notify = [&](const std::string& message) {
        if (starts_with(message, "READY=1")) {
            h.later([&] { daemon.request_stop("SIGTERM received"); });
        }
        if (starts_with(message, "STOPPING=1")) {
            h.later([&] {
                CHECK(daemon.phase() == Daemon::Phase::stopping);
                h.events.push_back("lines finished");
                lines.finished.done();
                h.later([&] {
                    CHECK(daemon.phase() == Daemon::Phase::stopping);  // mqtt still publishing offline
                    h.events.push_back("mqtt finished");
                    mqtt.finished.done();
                });
            });
        }
    };
    CHECK(h.run() == exit_ok);
    CHECK(h.events == std::vector<std::string>{"start lines", "start modbus-tcp", "start mqtt", "stop mqtt",
                                               "stop modbus-tcp", "stop lines", "lines finished", "mqtt finished"});
    CHECK(h.logged("<6>stopped\n"));
    CHECK(daemon.phase() == Daemon::Phase::stopped);
}

TEST_CASE("the stop timeout bounds the wait for a component that never finishes") {
    Harness h;
    h.options.stop_timeout = std::chrono::milliseconds{30};
    FakeComponent lines("lines", h.events);
    lines.needs_stop_ticket = true;
    auto& daemon = h.create();
    daemon.add_component(lines);
    h.manager.on_notify = [&](const std::string& message) {
        if (starts_with(message, "READY=1")) {
            h.later([&] { daemon.request_stop("SIGTERM received"); });
        }
    };
    const auto started = std::chrono::steady_clock::now();
    CHECK(h.run() == exit_ok);
    CHECK(std::chrono::steady_clock::now() - started >= std::chrono::milliseconds{30});
    CHECK(h.logged("<4>stop timeout (30 ms) expired: exiting without waiting for lines transaction in flight\n"));
    CHECK_FALSE(h.logged("<6>stopped\n"));
}

TEST_CASE("a second stop request while stopping exits at once") {
    Harness h;
    FakeComponent lines("lines", h.events);
    lines.needs_stop_ticket = true;
    auto& daemon = h.create();
    daemon.add_component(lines);
    h.manager.on_notify = [&](const std::string& message) {
        if (starts_with(message, "READY=1")) {
            h.later([&] { daemon.request_stop("SIGTERM received"); });
        }
        if (starts_with(message, "STOPPING=1")) {
            h.later([&] { daemon.request_stop("SIGINT received"); });
        }
    };
    CHECK(h.run() == exit_ok);
    CHECK(h.manager.count("STOPPING=1") == 1);
    CHECK(h.logged("<4>SIGINT received while stopping: exiting now, without waiting for lines transaction in "
                   "flight\n"));
}

TEST_CASE("a component that cannot start: the started ones stop, no READY, exit 1") {
    Harness h;
    FakeComponent lines("lines", h.events);
    FakeComponent tcp("modbus-tcp", h.events);
    FakeComponent mqtt("mqtt", h.events);
    lines.needs_ready_ticket = true;  // never ready: the failure must not wait for it
    tcp.fails_to_start = true;
    auto& daemon = h.create();
    daemon.add_component(lines);
    daemon.add_component(tcp);
    daemon.add_component(mqtt);
    CHECK(h.run() == exit_failure);
    CHECK(h.events == std::vector<std::string>{"start lines", "start modbus-tcp", "stop lines"});
    CHECK(h.manager.count("READY=1") == 0);
    CHECK(h.manager.count("STOPPING=1") == 1);
    CHECK(h.logged("<3>cannot start modbus-tcp: port /dev/ttyUSB7 is busy\n"));
}

TEST_CASE("a fatal error reported by a component stops the gateway with exit 1") {
    Harness h;
    FakeComponent lines("lines", h.events);
    auto& daemon = h.create();
    daemon.add_component(lines);
    h.manager.on_notify = [&](const std::string& message) {
        if (starts_with(message, "READY=1")) {
            h.later([&] { daemon.fail("Modbus TCP listener 0.0.0.0:502 closed: too many open files"); });
        }
    };
    CHECK(h.run() == exit_failure);
    CHECK(h.events == std::vector<std::string>{"start lines", "stop lines"});
    CHECK(h.logged("<3>Modbus TCP listener 0.0.0.0:502 closed: too many open files\n"));
}

TEST_CASE("an exception escaping a handler ends the loop with exit 1") {
    Harness h;
    h.create();
    h.manager.on_notify = [&](const std::string& message) {
        if (starts_with(message, "READY=1")) {
            h.later([] { throw std::runtime_error("register image corrupted"); });
        }
    };
    CHECK(h.run() == exit_failure);
    CHECK(h.logged("<2>internal error, exiting: register image corrupted\n"));
    CHECK(h.manager.messages.back() == "STOPPING=1");
}

TEST_CASE("reload requests while stopping are ignored") {
    Harness h;
    FakeComponent lines("lines", h.events);
    lines.needs_stop_ticket = true;
    auto& daemon = h.create();
    daemon.add_component(lines);
    h.manager.on_notify = [&](const std::string& message) {
        if (starts_with(message, "READY=1")) {
            h.later([&] { daemon.request_stop("SIGTERM received"); });
        }
        if (starts_with(message, "STOPPING=1")) {
            h.later([&] {
                daemon.request_reload();
                lines.finished.done();
            });
        }
    };
    CHECK(h.run() == exit_ok);
    CHECK(h.loads == 0);
    CHECK(h.manager.count("RELOADING=1") == 0);
    CHECK(h.logged("<6>reload ignored: the gateway is stopping\n"));
}
