// Huacheng R6 units as MQTT devices: the upstream pass-through polling the simulated
// controller (fieldbridge-sim --r6), the bridge and a real mosquitto.
#include <doctest/doctest.h>

#include <filesystem>

#include <nlohmann/json.hpp>

#include "broker_support.hpp"
#include "loop_support.hpp"
#include "northbound/mqtt/mqtt_bridge.hpp"
#include "northbound/mqtt/paho_client.hpp"
#include "northbound/mqtt/r6_source.hpp"
#include "sim_process.hpp"
#include "temp_dir.hpp"

namespace {

using namespace fbt;
using fieldbridge::test::SimProcess;
using nlohmann::json;
namespace fm = fieldbridge::northbound::mqtt;
namespace fu = fieldbridge::northbound::upstream;

}  // namespace

TEST_CASE("R6 units on MQTT: decoded state, alarm raise / clear, commands through the pass-through") {
    const fieldbridge::test::TempDir tmp("fb-mqtt-r6");
    const std::string dir = tmp.path().string();
    Mosquitto broker(free_port());
    broker.start();
    {
        const int r6_port = free_port();
        SimProcess sim({"--log-level", "warn", "--r6", "127.0.0.1:" + std::to_string(r6_port)});
        asio::io_context io;
        fieldbridge::config::UpstreamConfig upstream;
        upstream.name = "r6";
        upstream.host = "127.0.0.1";
        upstream.port = static_cast<std::uint16_t>(r6_port);
        upstream.poll_period = std::chrono::milliseconds{100};
        upstream.units = {fieldbridge::config::UpstreamUnitConfig{fieldbridge::core::UnitId{10}, fieldbridge::core::UnitId{1}, "robot"}};
        fu::UpstreamTarget target(io, upstream, fieldbridge::engine::LogSink{});
        target.start();

        fm::PahoOptions o;
        o.uri = broker.uri();
        o.client_id = "fieldbridge-r6-test";
        o.will = fm::Message{"r6t/gw/status", "offline", 1, true};
        fm::BridgeSettings s;
        s.prefix = "r6t/gw";
        s.throttle.min_interval = std::chrono::milliseconds{50};
        s.reconnect_initial = std::chrono::milliseconds{100};
        auto bridge = std::make_unique<fm::Bridge>(io, s, std::make_unique<fm::PahoClient>(io, o));
        auto sources = fm::make_r6_sources(io, target);
        REQUIRE(sources.size() == 1);
        CHECK(sources[0]->name() == "robot");
        bridge->set_sources(sources);
        bridge->start();
        Observer observer(broker.uri(), "r6t/gw/#");

        const auto state = expect(io, observer, "r6t/gw/robot/state", [](const json& j) {
            return j["online"] == true && j["fields"].contains("mode") && j["fields"].contains("moving");
        });
        REQUIRE(state);
        CHECK((*state)["type"] == "r6");
        CHECK((*state)["quality"] == "good");
        CHECK_FALSE((*state)["raw"]["holding"].empty());

        std::size_t from = observer.count();
        CHECK(sim.control("r6 alarm 805").rfind("ok", 0) == 0);
        const auto raised = expect(io, observer, "r6t/gw/robot/alarm", [](const json& j) { return j["event"] == "raised"; },
                                   from);
        REQUIRE(raised);
        CHECK((*raised)["code"] == "r6_alarm_805");

        from = observer.count();
        observer.publish("r6t/gw/robot/cmd", R"({"id":"c","op":"clear_alarm","resume":"next"})");
        auto result = expect(io, observer, "r6t/gw/robot/cmd/result", [](const json& j) { return j["id"] == "c"; }, from);
        REQUIRE(result);
        CHECK((*result)["ok"] == true);
        CHECK(expect(io, observer, "r6t/gw/robot/alarm", [](const json& j) {
            return j["event"] == "cleared" && j["code"] == "r6_alarm_805";
        }, from));
        observer.publish("r6t/gw/robot/cmd", R"({"id":"s","op":"global_speed","percent":25.5})");
        result = expect(io, observer, "r6t/gw/robot/cmd/result", [](const json& j) { return j["id"] == "s"; }, from);
        REQUIRE(result);
        CHECK((*result)["ok"] == true);
        observer.publish("r6t/gw/robot/cmd", R"({"id":"x","op":"global_speed","percent":101})");
        result = expect(io, observer, "r6t/gw/robot/cmd/result", [](const json& j) { return j["id"] == "x"; }, from);
        REQUIRE(result);
        CHECK((*result)["error"] == "out_of_range");
        observer.publish("r6t/gw/robot/cmd", R"({"id":"p","op":"stop"})");
        result = expect(io, observer, "r6t/gw/robot/cmd/result", [](const json& j) { return j["id"] == "p"; }, from);
        REQUIRE(result);
        CHECK((*result)["ok"] == true);

        bridge.reset();
        fm::detach_r6_sources(sources);
        target.stop();
        io.restart();
        io.run_for(std::chrono::milliseconds{50});
    }
    std::error_code ignored;
    std::filesystem::remove_all(dir, ignored);
}
