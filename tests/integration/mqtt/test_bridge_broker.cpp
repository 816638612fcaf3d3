// The bridge with the real Paho client against a real mosquitto started by the test
// (127.0.0.1, free port): availability, retained state, alarms, commands, broker
// outage and return, a list of brokers whose first is absent, clean stop, last will
// when the process is killed.
#include <doctest/doctest.h>

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <nlohmann/json.hpp>

#include "broker_support.hpp"
#include "fake_source.hpp"
#include "run_until.hpp"
#include "northbound/mqtt/mqtt_bridge.hpp"
#include "northbound/mqtt/paho_client.hpp"

extern char** environ;

namespace {

using namespace fbt;
using namespace std::chrono_literals;
using nlohmann::json;

constexpr auto wait_limit = 10s;

fm::BridgeSettings settings(const std::string& prefix) {
    fm::BridgeSettings s;
    s.prefix = prefix;
    s.qos = 1;
    s.throttle.min_interval = 50ms;
    s.throttle.heartbeat = 60s;
    s.throttle.deadband = {{"position_mm", 0.05}};
    s.alarms.comm_clear_hold = 200ms;
    s.diag_period = 1s;
    s.reconnect_initial = 100ms;
    s.reconnect_max = 400ms;
    s.watch_period = 200ms;
    return s;
}

std::unique_ptr<fm::Client> paho(asio::io_context& io, const Mosquitto& broker, const std::string& prefix) {
    fm::PahoOptions o;
    o.uri = broker.uri();
    o.client_id = "fieldbridge-test-" + prefix;
    o.keep_alive = 5s;
    o.will = fm::Message{prefix + "/status", "offline", 1, true};
    return std::make_unique<fm::PahoClient>(io, o);
}

using fieldbridge::test_support::run_until;

/// Runs the loop until the observer got a message on @p topic matching @p match
/// (from message index @p from on).
std::optional<Received> expect(asio::io_context& io, Observer& observer, const std::string& topic,
                               const std::function<bool(const json&, const Received&)>& match, std::size_t from = 0) {
    std::optional<Received> found;
    const auto matcher = [&](const Received& r) {
        const json j = json::parse(r.payload, nullptr, false);
        return match(j, r);
    };
    run_until(io, [&] {
        found = observer.wait_for(topic, matcher, 0ms, from);
        return found.has_value();
    }, wait_limit);
    return found;
}

/// A rig: broker, observer on the prefix, a bridge with one fake XEG "g1".
struct Rig {
    explicit Rig(std::string p) : prefix(std::move(p)), broker(free_port()) {
        broker.start();
        observer = std::make_unique<Observer>(broker.uri(), prefix + "/#");
        source = std::make_shared<FakeSource>(io, "g1");
        bridge = std::make_unique<fm::Bridge>(io, settings(prefix), paho(io, broker, prefix));
        bridge->set_sources({source});
        bridge->start();
        REQUIRE(run_until(io, [&] { return bridge->connected(); }));
    }
    ~Rig() {
        bridge.reset();
        io.restart();
        io.run_for(50ms);
    }

    std::optional<json> expect_json(const std::string& leaf,
                                    const std::function<bool(const json&)>& match, std::size_t from = 0) {
        const auto got = expect(io, *observer, prefix + "/" + leaf,
                                [&](const json& j, const Received&) { return match(j); }, from);
        if (!got) return std::nullopt;
        return json::parse(got->payload);
    }

    json command(const std::string& payload) {
        const std::size_t from = observer->count();
        observer->publish(prefix + "/g1/cmd", payload);
        const auto result = expect_json("g1/cmd/result", [](const json&) { return true; }, from);
        REQUIRE(result);
        return *result;
    }

    asio::io_context io;
    std::string prefix;
    Mosquitto broker;
    std::unique_ptr<Observer> observer;
    std::shared_ptr<FakeSource> source;
    std::unique_ptr<fm::Bridge> bridge;
};

}  // namespace

TEST_CASE("bridge + mosquitto: availability online, state retained and updated on change (deadband applies)") {
    Rig rig("t1/gw");
    const auto online = expect(rig.io, *rig.observer, "t1/gw/status",
                               [](const json&, const Received& r) { return r.payload == "online"; });
    REQUIRE(online);
    auto state = rig.expect_json("g1/state", [](const json& j) { return j["fields"]["position_mm"] == 10.0; });
    REQUIRE(state);
    CHECK((*state)["device"] == "g1");
    CHECK((*state)["online"] == true);
    CHECK((*state)["quality"] == "good");
    CHECK((*state)["raw"]["input"]["0x0300"] == 1000);

    // Below the deadband (0.05): no new state, though six min_intervals pass; above:
    // published. Without the deadband 10.02 goes out within one min_interval (50 ms).
    std::size_t from = rig.observer->count();
    const auto states_since = [&](std::size_t first) {
        std::size_t n = 0;
        const auto all = rig.observer->messages();
        for (std::size_t i = first; i < all.size(); ++i) n += all[i].topic == "t1/gw/g1/state" ? 1 : 0;
        return n;
    };
    rig.source->set_position(10.02);
    CHECK_FALSE(run_until(rig.io, [&] { return states_since(from) > 0; }, 300ms));
    CHECK(states_since(from) == 0);
    rig.source->set_position(17.0);
    state = rig.expect_json("g1/state", [](const json& j) { return j["fields"]["position_mm"] == 17.0; }, from);
    REQUIRE(state);
    for (const auto& m : rig.observer->messages()) {
        if (m.topic == "t1/gw/g1/state") CHECK(json::parse(m.payload)["fields"]["position_mm"] != 10.02);
    }

    // A subscriber that comes later gets the retained state and status.
    Observer late(rig.broker.uri(), "t1/gw/#");
    CHECK(late.wait_for("t1/gw/g1/state", [](const Received& r) {
        return r.retained && json::parse(r.payload)["fields"]["position_mm"] == 17.0;
    }, 5s));
    CHECK(late.wait_for("t1/gw/status", [](const Received& r) { return r.retained && r.payload == "online"; }, 5s));

    // Diagnostics every period, with the MQTT counters.
    const auto diag = rig.expect_json("diag", [](const json& j) { return j.contains("mqtt"); });
    REQUIRE(diag);
    CHECK((*diag)["mqtt"]["connects"] == 1);
}

TEST_CASE("bridge + mosquitto: an alarm raises and clears on the alarm topic, with a retained active set") {
    Rig rig("t2/gw");
    const fe::Alarm alarm{"move_alarm", "move alarm", fe::Severity::error, "input 0x0301"};
    std::size_t from = rig.observer->count();
    rig.source->set_alarms({alarm});
    auto raised = rig.expect_json("g1/alarm", [](const json& j) { return j["event"] == "raised"; }, from);
    REQUIRE(raised);
    CHECK((*raised)["code"] == "move_alarm");
    CHECK((*raised)["severity"] == "error");
    auto set = rig.expect_json("g1/alarm", [](const json& j) { return j["event"] == "active" && j["alarms"].size() == 1; },
                               from);
    REQUIRE(set);

    from = rig.observer->count();
    rig.source->set_alarms({});
    auto cleared = rig.expect_json("g1/alarm", [](const json& j) { return j["event"] == "cleared"; }, from);
    REQUIRE(cleared);
    CHECK((*cleared)["code"] == "move_alarm");
    REQUIRE(rig.expect_json("g1/alarm", [](const json& j) { return j["event"] == "active" && j["alarms"].empty(); }, from));

    // Communication loss: raised when offline, cleared after the hold once back.
    from = rig.observer->count();
    rig.source->set_online(false);
    REQUIRE(rig.expect_json("g1/alarm", [](const json& j) { return j["event"] == "raised" && j["code"] == "comm_loss"; },
                            from));
    REQUIRE(rig.expect_json("g1/state", [](const json& j) { return j["online"] == false && j["quality"] == "offline"; },
                            from));
    rig.source->set_online(true);
    REQUIRE(rig.expect_json("g1/alarm", [](const json& j) { return j["event"] == "cleared" && j["code"] == "comm_loss"; },
                            from));

    // The retained message is the set.
    Observer late(rig.broker.uri(), "t2/gw/g1/alarm");
    CHECK(late.wait_for("t2/gw/g1/alarm", [](const Received& r) {
        return r.retained && json::parse(r.payload)["event"] == "active";
    }, 5s));
}

TEST_CASE("bridge + mosquitto: commands are executed and answered; invalid ones get an error and send nothing") {
    Rig rig("t3/gw");
    json result = rig.command(R"({"id":"m1","op":"move","position_mm":17,"speed_mm_s":20})");
    CHECK(result["id"] == "m1");
    CHECK(result["ok"] == true);
    CHECK(result["op"] == "move");
    REQUIRE(rig.source->executed.size() == 1);
    CHECK(rig.source->executed[0] == fp::Request{fp::WriteMultipleRegistersRequest{0x0630, {1700, 2000, 1}}});

    for (const char* op : {"reset", "stop"}) {
        result = rig.command(std::string(R"({"id":7,"op":")") + op + "\"}");
        CHECK(result["ok"] == true);
    }
    CHECK(rig.command(R"({"id":8,"op":"trigger","index":3})")["ok"] == true);
    CHECK(rig.command(R"({"id":9,"op":"expert","direction":0,"stroke_mm":5,"speed_mm_s":5,"holding_stroke_mm":1,)"
                      R"("holding_speed_mm_s":1,"force_pct":50})")["ok"] == true);
    CHECK(rig.command(R"({"id":10,"op":"write_registers","address":1552,"values":[1]})")["ok"] == true);
    CHECK(rig.source->executed.size() == 6);

    // Invalid: nothing reaches the source.
    const std::size_t before = rig.source->executed.size();
    result = rig.command(R"({"id":"x","op":"fly"})");
    CHECK(result["ok"] == false);
    CHECK(result["error"] == "unknown_op");
    CHECK(result["id"] == "x");
    CHECK(rig.command(R"({"id":"y","op":"move","position_mm":17})")["error"] == "missing_field");
    CHECK(rig.command(R"({"id":"z","op":"move","position_mm":-3,"speed_mm_s":1})")["error"] == "out_of_range");
    CHECK(rig.command("{not json")["error"] == "bad_json");
    result = rig.command(R"({"id":"p","op":"move","position_mm":70,"speed_mm_s":1})");  // the profile refuses
    CHECK(result["error"] == "rejected");
    CHECK(result["exception"] == 3);
    CHECK(rig.source->executed.size() == before);

    // The device answers with an exception / does not answer.
    rig.source->answers.push_back(fp::ExceptionResponse{fp::fc::write_multiple_registers,
                                                        fp::ExceptionCode::server_device_failure});
    result = rig.command(R"({"id":"d","op":"reset"})");
    CHECK(result["error"] == "device_exception");
    CHECK(result["exception"] == 4);
    rig.source->answers.push_back(fp::ExceptionResponse{fp::fc::write_single_register,
                                                        fp::ExceptionCode::gateway_target_failed});
    CHECK(rig.command(R"({"id":"t","op":"stop"})")["error"] == "no_answer");

    // Disabled per device; unknown device.
    rig.source->commands_enabled_ = false;
    const std::size_t count = rig.source->executed.size();
    CHECK(rig.command(R"({"id":"q","op":"stop"})")["error"] == "commands_disabled");
    CHECK(rig.source->executed.size() == count);
    const std::size_t from = rig.observer->count();
    rig.observer->publish("t3/gw/nobody/cmd", R"({"id":1,"op":"stop"})");
    const auto unknown = rig.expect_json("nobody/cmd/result", [](const json&) { return true; }, from);
    REQUIRE(unknown);
    CHECK((*unknown)["error"] == "unknown_device");
}

TEST_CASE("bridge + mosquitto: a broker outage leaves the bridge running; state and availability are republished") {
    Rig rig("t4/gw");
    REQUIRE(rig.expect_json("g1/state", [](const json& j) { return j["fields"]["position_mm"] == 10.0; }));
    rig.observer.reset();
    rig.broker.stop();
    REQUIRE(run_until(rig.io, [&] { return !rig.bridge->connected(); }));
    // Changes while the broker is away are not lost: the newest state goes out later.
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < 200; ++i) rig.source->set_position(20.0 + i * 0.1);
    rig.io.restart();
    rig.io.run_for(500ms);  // reconnect attempts fail meanwhile
    // Nothing the bridge does while the broker is away takes loop time worth noting.
    CHECK(std::chrono::steady_clock::now() - t0 < 5s);
    CHECK(rig.bridge->stats().connect_failures >= 1);
    CHECK(rig.bridge->stats().queued < 50);

    rig.broker.start();  // a fresh broker: no retained messages at all
    REQUIRE(run_until(rig.io, [&] { return rig.bridge->connected(); }));
    rig.observer = std::make_unique<Observer>(rig.broker.uri(), "t4/gw/#");
    REQUIRE(expect(rig.io, *rig.observer, "t4/gw/status", [](const json&, const Received& r) {
        return r.retained && r.payload == "online";
    }));
    const auto state = rig.expect_json("g1/state", [](const json& j) {
        return std::abs(j["fields"]["position_mm"].get<double>() - 39.9) < 1e-6;
    });
    REQUIRE(state);
    CHECK(rig.expect_json("g1/alarm", [](const json& j) { return j["event"] == "active"; }));
    CHECK(rig.bridge->stats().connects == 2);
}

TEST_CASE("bridge + mosquitto: with two brokers and the first absent, the bridge walks to the second") {
    Mosquitto broker(free_port());
    broker.start();
    Observer observer(broker.uri(), "t7/gw/status");
    asio::io_context io;
    const std::string absent = "tcp://127.0.0.1:" + std::to_string(free_port());  // nothing listens
    fm::PahoOptions o;
    o.uri = absent;
    o.servers = {absent, broker.uri()};
    o.client_id = "fieldbridge-test-t7";
    o.keep_alive = 5s;
    o.will = fm::Message{"t7/gw/status", "offline", 1, true};
    fm::Bridge bridge(io, settings("t7/gw"), std::make_unique<fm::PahoClient>(io, o));
    bridge.start();
    REQUIRE(run_until(io, [&] { return bridge.connected(); }));
    CHECK(bridge.stats().connect_failures >= 1);
    CHECK(observer.wait_for("t7/gw/status", [](const Received& r) { return r.payload == "online"; }, 5s));
    bool stopped = false;
    bridge.stop([&] { stopped = true; });
    REQUIRE(run_until(io, [&] { return stopped; }));
}

TEST_CASE("bridge + mosquitto: a clean stop publishes offline") {
    Rig rig("t5/gw");
    bool stopped = false;
    rig.bridge->stop([&] { stopped = true; });
    REQUIRE(run_until(rig.io, [&] { return stopped; }));
    CHECK_FALSE(rig.bridge->connected());
    Observer late(rig.broker.uri(), "t5/gw/status");
    CHECK(late.wait_for("t5/gw/status", [](const Received& r) { return r.retained && r.payload == "offline"; }, 5s));
}

TEST_CASE("bridge + mosquitto: the last will shows offline when the gateway process is killed") {
    Mosquitto broker(free_port());
    broker.start();
    Observer observer(broker.uri(), "t6/gw/status");
    std::string program = FB_MQTT_WILL_PEER;
    std::vector<std::string> args{program, std::to_string(broker.port()), "t6/gw"};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    pid_t pid = -1;
    REQUIRE(::posix_spawn(&pid, program.c_str(), nullptr, nullptr, argv.data(), environ) == 0);
    const bool online = observer.wait_for("t6/gw/status", [](const Received& r) { return r.payload == "online"; }, wait_limit)
                            .has_value();
    ::kill(pid, SIGKILL);
    int status = 0;
    ::waitpid(pid, &status, 0);
    REQUIRE(online);
    CHECK(observer.wait_for("t6/gw/status", [](const Received& r) { return r.payload == "offline"; }, wait_limit));
}
