// The bridge over a scripted client: bounded in-flight and outbox while the broker is
// slow, back-off of reconnection attempts, walking a list of brokers, clean stop, retained commands refused,
// commands that depend on the device's registers.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "fake_source.hpp"
#include "northbound/mqtt/mqtt_bridge.hpp"

namespace {

using namespace fbt;
using namespace std::chrono_literals;
using nlohmann::json;

/// A client whose broker answers only when the test says so.
class ScriptedClient final : public fm::Client {
public:
    struct Log {
        std::vector<fm::Message> published;
        std::vector<std::uint64_t> ids;
        std::vector<fe::TimePoint> connects;
        std::vector<std::string> subscriptions;
        bool disconnected = false;
        fm::ClientEvents events;
        bool connected = false;
        bool accept_connect = true;
        std::size_t servers = 1;                  ///< brokers of the list
        std::size_t server = 0;                   ///< the one select_server() chose
        std::vector<std::size_t> connect_servers;  ///< the broker of each connect()
    };
    explicit ScriptedClient(asio::io_context& io, std::shared_ptr<Log> log) : io_(io), log_(std::move(log)) {}

    void set_events(fm::ClientEvents events) override { log_->events = std::move(events); }
    void connect() override {
        log_->connects.push_back(fe::Clock::now());
        log_->connect_servers.push_back(log_->server);
        asio::post(io_, [log = log_] {
            if (log->accept_connect) {
                log->connected = true;
                if (log->events.connected) log->events.connected();
            } else if (log->events.connect_failed) {
                log->events.connect_failed("connection refused");
            }
        });
    }
    std::uint64_t publish(const fm::Message& message) override {
        if (!log_->connected) return 0;
        log_->published.push_back(message);
        log_->ids.push_back(next_);
        return next_++;
    }
    void subscribe(const std::string& filter, int) override { log_->subscriptions.push_back(filter); }
    void disconnect(std::chrono::milliseconds, std::function<void()> done) override {
        log_->connected = false;
        log_->disconnected = true;
        asio::post(io_, std::move(done));
    }
    bool connected() const override { return log_->connected; }
    std::size_t server_count() const override { return log_->servers; }
    void select_server(std::size_t index) override { log_->server = index; }

private:
    asio::io_context& io_;
    std::shared_ptr<Log> log_;
    std::uint64_t next_ = 1;
};

fm::BridgeSettings bridge_settings() {
    fm::BridgeSettings s;
    s.prefix = "p";
    s.throttle.min_interval = 0ms;
    s.max_in_flight = 4;
    s.outbox_capacity = 8;
    s.reconnect_initial = 20ms;
    s.reconnect_max = 80ms;
    s.watch_period = 50ms;
    return s;
}

void run(asio::io_context& io, std::chrono::milliseconds d) {
    io.restart();
    io.run_for(d);
}

}  // namespace

TEST_CASE("bridge: at most max_in_flight unacknowledged publications; the rest wait, bounded, newest state kept") {
    asio::io_context io;
    auto log = std::make_shared<ScriptedClient::Log>();
    fm::Bridge bridge(io, bridge_settings(), std::make_unique<ScriptedClient>(io, log));
    auto source = std::make_shared<FakeSource>(io, "g1");
    bridge.set_sources({source});
    bridge.start();
    run(io, 30ms);
    REQUIRE(log->connected);
    CHECK(log->subscriptions == std::vector<std::string>{"p/+/cmd"});
    REQUIRE(!log->published.empty());
    CHECK(log->published[0].topic == "p/status");
    CHECK(log->published[0].payload == "online");
    CHECK(log->published[0].retained);

    // The broker acknowledges nothing: many changes later, still 4 in flight and a
    // bounded outbox holding the newest state.
    for (int i = 0; i < 100; ++i) {
        source->set_position(20.0 + i);
        run(io, 2ms);
    }
    CHECK(log->published.size() == 4);
    const auto stats = bridge.stats();
    CHECK(stats.in_flight == 4);
    CHECK(stats.queued <= 8);
    // Acknowledge everything: the newest state goes out.
    for (std::size_t k = 0; k < 20 && bridge.stats().in_flight > 0; ++k) {
        const auto ids = log->ids;
        for (auto id : ids) log->events.published(id, true);
        log->ids.clear();
        run(io, 5ms);
    }
    const auto last_state = [&] {
        for (auto it = log->published.rbegin(); it != log->published.rend(); ++it) {
            if (it->topic == "p/g1/state") return json::parse(it->payload);
        }
        return json();
    }();
    CHECK(last_state["fields"]["position_mm"] == 119.0);
}

TEST_CASE("bridge: reconnection attempts back off, doubling up to the maximum") {
    asio::io_context io;
    auto log = std::make_shared<ScriptedClient::Log>();
    log->accept_connect = false;
    fm::Bridge bridge(io, bridge_settings(), std::make_unique<ScriptedClient>(io, log));
    bridge.start();
    const auto until = std::chrono::steady_clock::now() + 2s;
    while (log->connects.size() < 6 && std::chrono::steady_clock::now() < until) run(io, 5ms);
    REQUIRE(log->connects.size() >= 6);
    // Gaps: >= 20, 40, 80, 80, 80 ms (timers never fire early).
    const fe::Duration expected[] = {20ms, 40ms, 80ms, 80ms, 80ms};
    for (std::size_t i = 0; i < 5; ++i) CHECK(log->connects[i + 1] - log->connects[i] >= expected[i]);
    CHECK(bridge.stats().connect_failures >= 5);
    for (const std::size_t server : log->connect_servers) CHECK(server == 0);  // one broker: always it
    log->accept_connect = true;
    while (!bridge.connected() && std::chrono::steady_clock::now() < until + 1s) run(io, 5ms);
    CHECK(bridge.connected());
}

TEST_CASE("bridge: a clean stop publishes offline, waits for it, then disconnects") {
    asio::io_context io;
    auto log = std::make_shared<ScriptedClient::Log>();
    fm::Bridge bridge(io, bridge_settings(), std::make_unique<ScriptedClient>(io, log));
    bridge.start();
    run(io, 20ms);
    for (auto id : log->ids) log->events.published(id, true);
    log->ids.clear();
    bool stopped = false;
    bridge.stop([&] { stopped = true; });
    REQUIRE_FALSE(log->published.empty());
    CHECK(log->published.back().payload == "offline");
    CHECK(log->published.back().retained);
    run(io, 20ms);
    CHECK_FALSE(log->disconnected);  // waiting for the acknowledgement
    log->events.published(log->ids.back(), true);
    run(io, 20ms);
    CHECK(log->disconnected);
    CHECK(stopped);
}

TEST_CASE("bridge: a retained command is never executed") {
    asio::io_context io;
    auto log = std::make_shared<ScriptedClient::Log>();
    fm::Bridge bridge(io, bridge_settings(), std::make_unique<ScriptedClient>(io, log));
    auto source = std::make_shared<FakeSource>(io, "g1");
    bridge.set_sources({source});
    bridge.start();
    run(io, 20ms);
    log->events.message(fm::Message{"p/g1/cmd", R"({"id":1,"op":"stop"})", 1, true});
    for (auto id : log->ids) log->events.published(id, true);
    run(io, 20ms);
    CHECK(source->executed.empty());
    bool answered = false;
    for (const auto& m : log->published) {
        if (m.topic == "p/g1/cmd/result") {
            answered = true;
            CHECK(json::parse(m.payload)["error"] == "retained");
        }
    }
    CHECK(answered);
    // Not retained: executed.
    log->events.message(fm::Message{"p/g1/cmd", R"({"id":2,"op":"stop"})", 1, false});
    run(io, 20ms);
    CHECK(source->executed.size() == 1);
}

TEST_CASE("bridge: WTEC grip uses the device's init direction; unknown, nothing is sent") {
    asio::io_context io;
    auto log = std::make_shared<ScriptedClient::Log>();
    fm::Bridge bridge(io, bridge_settings(), std::make_unique<ScriptedClient>(io, log));
    auto source = std::make_shared<FakeSource>(io, "w1", fe::wtec_operations());
    bridge.set_sources({source});
    bridge.start();
    run(io, 20ms);
    const auto result_of = [&](int id) {
        json found;
        for (const auto& m : log->published) {
            if (m.topic == "p/w1/cmd/result" && json::parse(m.payload)["id"] == id) found = json::parse(m.payload);
        }
        return found;
    };
    std::size_t acked = 0;
    const auto settle = [&] {  // the broker acknowledges everything published so far
        for (int round = 0; round < 4; ++round) {
            run(io, 10ms);
            for (; acked < log->ids.size(); ++acked) log->events.published(log->ids[acked], true);
        }
    };
    // The image has no holding 0x0300 yet (only the fake's input 0x0300).
    log->events.message(fm::Message{"p/w1/cmd", R"({"id":1,"op":"grip"})", 1, false});
    settle();
    CHECK(source->executed.empty());
    const json refused = result_of(1);
    CHECK(refused["ok"] == false);
    CHECK(refused["error"] == "state_unknown");
    CHECK(refused["message"].get<std::string>().find("init direction") != std::string::npos);
    // Direction 2 (homes at the closed end): closing is 0 %.
    source->add_register(fm::RawRegister{fe::Table::holding, 0x0300, 2});
    log->events.message(fm::Message{"p/w1/cmd", R"({"id":2,"op":"grip"})", 1, false});
    settle();
    REQUIRE(source->executed.size() == 1);
    CHECK(source->executed[0] == fp::Request{fp::WriteSingleRegisterRequest{0x0105, 0}});
    CHECK(result_of(2)["ok"] == true);
}

TEST_CASE("bridge: an oversized command is refused unread; a long id is echoed cut; duplicate keys do nothing") {
    asio::io_context io;
    auto log = std::make_shared<ScriptedClient::Log>();
    auto s = bridge_settings();
    s.max_command_bytes = 256;
    s.max_command_id_length = 16;
    s.outbox_capacity = 64;
    fm::Bridge bridge(io, s, std::make_unique<ScriptedClient>(io, log));
    auto source = std::make_shared<FakeSource>(io, "g1");
    bridge.set_sources({source});
    bridge.start();
    run(io, 20ms);
    std::size_t acked = 0;
    std::vector<json> results;
    const auto settle = [&] {
        for (int round = 0; round < 4; ++round) {
            run(io, 10ms);
            for (; acked < log->ids.size(); ++acked) log->events.published(log->ids[acked], true);
        }
        results.clear();
        for (const auto& m : log->published) {
            if (m.topic == "p/g1/cmd/result") results.push_back(json::parse(m.payload));
        }
    };
    const std::string huge_id(300, 'x');
    log->events.message(fm::Message{"p/g1/cmd", R"({"id":")" + huge_id + R"(","op":"stop"})", 1, false});
    settle();
    REQUIRE(results.size() == 1);
    CHECK(results[0]["error"] == "too_large");
    CHECK(results[0]["id"].is_null());
    CHECK(bridge.stats().commands_too_large == 1);
    const std::string long_id(200, 'y');
    log->events.message(fm::Message{"p/g1/cmd", R"({"id":")" + long_id + R"(","op":"stop"})", 1, false});
    settle();
    REQUIRE(results.size() == 2);
    CHECK(results[1]["ok"] == true);
    CHECK(results[1]["id"] == std::string(16, 'y'));
    CHECK(source->executed.size() == 1);
    log->events.message(fm::Message{"p/g1/cmd", R"({"id":10,"op":"stop","op":"reset"})", 1, false});
    settle();
    REQUIRE(results.size() == 3);
    CHECK(results[2]["error"] == "bad_json");
    CHECK(source->executed.size() == 1);
    // The client's inbound drops are counted.
    log->events.inbound_dropped(5);
    CHECK(bridge.stats().commands_dropped == 5);
}

namespace {

/// A probe whose answer the test sets.
class ScriptedProbe final : public fm::BrokerProbe {
public:
    explicit ScriptedProbe(asio::io_context& io, std::shared_ptr<bool> reachable, std::shared_ptr<int> probes)
        : io_(io), reachable_(std::move(reachable)), probes_(std::move(probes)) {}
    void probe(std::chrono::milliseconds, std::function<void(bool)> done) override {
        ++*probes_;
        asio::post(io_, [done = std::move(done), reachable = *reachable_] { done(reachable); });
    }
    void cancel() override {}

private:
    asio::io_context& io_;
    std::shared_ptr<bool> reachable_;
    std::shared_ptr<int> probes_;
};

/// A bridge whose broker refuses every attempt, with a scripted probe.
struct ProbeRig {
    ProbeRig(bool port_open, fe::Duration initial, fe::Duration max) {
        log->accept_connect = false;
        *reachable = port_open;
        auto settings = bridge_settings();
        settings.reconnect_initial = initial;
        settings.reconnect_max = max;
        settings.probe_period = 20ms;
        bridge = std::make_unique<fm::Bridge>(io, settings, std::make_unique<ScriptedClient>(io, log),
                                              fe::LogSink{}, std::make_unique<ScriptedProbe>(io, reachable, probes));
        bridge->start();
    }
    asio::io_context io;
    std::shared_ptr<ScriptedClient::Log> log = std::make_shared<ScriptedClient::Log>();
    std::shared_ptr<bool> reachable = std::make_shared<bool>(false);
    std::shared_ptr<int> probes = std::make_shared<int>(0);
    std::unique_ptr<fm::Bridge> bridge;
};

}  // namespace

TEST_CASE("bridge: a broker seen down is connected to as soon as its port accepts again, not after the back-off") {
    ProbeRig rig(false, 10ms, 10s);
    // Waits of 10, 20, 40, 80, 160 ms, then 320 ms: probed every 20 ms from the third on.
    const auto until = std::chrono::steady_clock::now() + 3s;
    while (rig.bridge->stats().connect_failures < 6 && std::chrono::steady_clock::now() < until) run(rig.io, 2ms);
    REQUIRE(rig.bridge->stats().connect_failures == 6);
    CHECK(*rig.probes > 0);
    // The broker is back at the start of a 320 ms wait: connected within about one
    // probe period.
    rig.log->accept_connect = true;
    *rig.reachable = true;
    const auto back = fe::Clock::now();
    while (!rig.bridge->connected() && std::chrono::steady_clock::now() < until) run(rig.io, 2ms);
    REQUIRE(rig.bridge->connected());
    CHECK(rig.log->connects.size() == 7);
    CHECK(rig.log->connects.back() - back < 150ms);
}

TEST_CASE("bridge: a reachable broker that refuses the connection is tried only at the back-off's pace") {
    ProbeRig rig(true, 100ms, 400ms);
    run(rig.io, 750ms);  // attempts at 0, 100, 300, 700 ms
    CHECK(*rig.probes > 5);
    CHECK(rig.log->connects.size() <= 4);
    for (std::size_t i = 1; i < rig.log->connects.size(); ++i) {
        CHECK(rig.log->connects[i] - rig.log->connects[i - 1] >= 100ms);
    }
}

TEST_CASE("bridge: events in flight when the connection breaks are sent again first, in order, on the next one") {
    asio::io_context io;
    auto log = std::make_shared<ScriptedClient::Log>();
    fm::Bridge bridge(io, bridge_settings(), std::make_unique<ScriptedClient>(io, log));
    auto source = std::make_shared<FakeSource>(io, "g1");
    bridge.set_sources({source});
    bridge.start();
    run(io, 30ms);
    REQUIRE(log->connected);
    for (auto id : log->ids) log->events.published(id, true);
    log->ids.clear();
    run(io, 10ms);
    const auto before = log->published.size();
    source->set_alarms({fe::Alarm{"a1", "test alarm", fe::Severity::error, "input 0x0301"}});  // raised event + active set, handed over
    run(io, 20ms);
    REQUIRE(log->published.size() > before);
    // Paho fails the unconfirmed publications, then reports the loss.
    log->connected = false;
    for (auto id : log->ids) log->events.published(id, false);
    log->ids.clear();
    log->events.connection_lost("broker went away");
    source->set_alarms({});  // made while disconnected
    run(io, 200ms);             // back-off, then connected again
    REQUIRE(log->connected);
    std::vector<std::string> events;
    for (std::size_t i = before; i < log->published.size(); ++i) {
        const auto& m = log->published[i];
        if (m.topic != "p/g1/alarm" || m.retained) continue;
        const auto body = json::parse(m.payload);
        events.push_back(body["event"].get<std::string>() + " " + body["code"].get<std::string>());
    }
    CHECK(events == std::vector<std::string>{"raised a1", "raised a1", "cleared a1"});
    CHECK(bridge.stats().resent == 1);
}

TEST_CASE("bridge: with several brokers, a failed attempt or a lost connection moves to the next one, wrapping") {
    asio::io_context io;
    auto log = std::make_shared<ScriptedClient::Log>();
    log->servers = 3;
    log->accept_connect = false;
    fm::Bridge bridge(io, bridge_settings(), std::make_unique<ScriptedClient>(io, log));
    bridge.start();
    const auto until = std::chrono::steady_clock::now() + 2s;
    while (log->connect_servers.size() < 4 && std::chrono::steady_clock::now() < until) run(io, 5ms);
    REQUIRE(log->connect_servers.size() >= 4);
    CHECK(log->connect_servers[0] == 0);
    CHECK(log->connect_servers[1] == 1);
    CHECK(log->connect_servers[2] == 2);
    CHECK(log->connect_servers[3] == 0);
    log->accept_connect = true;
    while (!bridge.connected() && std::chrono::steady_clock::now() < until + 1s) run(io, 5ms);
    REQUIRE(bridge.connected());
    const std::size_t on = log->connect_servers.back();
    const std::size_t attempts = log->connect_servers.size();
    log->connected = false;
    log->events.connection_lost("broker gone");
    while (log->connect_servers.size() == attempts && std::chrono::steady_clock::now() < until + 2s) run(io, 5ms);
    REQUIRE(log->connect_servers.size() > attempts);
    CHECK(log->connect_servers.back() == (on + 1) % 3);
}
