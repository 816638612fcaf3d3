// The MQTT component over the real line engine, a simulated XEG gripper
// (fieldbridge-sim on a pseudo-terminal) and a real mosquitto: state follows the
// gripper's motion, an injected alarm raises and clears, a command moves the
// gripper, a broker outage does not disturb the device's requests, and a clean stop
// publishes offline.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>
#include <spdlog/sinks/null_sink.h>
#include <spdlog/spdlog.h>

#include "broker_support.hpp"
#include "loop_support.hpp"
#include "sim_process.hpp"
#include "app/mqtt_component.hpp"
#include "config/config_loader.hpp"
#include "daemon/completion_barrier.hpp"
#include "engine/engine.hpp"
#include "temp_dir.hpp"

namespace {

using namespace fbt;
using namespace std::chrono_literals;
using fieldbridge::test::SimProcess;
using nlohmann::json;
namespace fe = fieldbridge::engine;
namespace fa = fieldbridge::app;
namespace fp = fieldbridge::protocol;
namespace fd = fieldbridge::daemon;

}  // namespace

TEST_CASE("MQTT component + engine + simulated XEG + mosquitto") {
    const fieldbridge::test::TempDir tmp("fb-mqtt-engine");
    const std::string dir = tmp.path().string();
    Mosquitto broker(free_port());
    broker.start();
    {
        SimProcess sim({"--log-level", "warn", "--bus", "{dir}/line-a:hiwin-xeg@1"});
        std::ofstream(dir + "/config.yaml") << "gateway:\n  id: simtest\n"
                                            << "lines:\n  - name: line-a\n    port: " << sim.path("line-a") << "\n"
                                            << "    devices:\n      - name: g1\n        type: hiwin-xeg\n"
                                            << "        address: 1\n        unit_id: 1\n"
                                            << "mqtt:\n  uri: " << broker.uri() << "\n  prefix: sim/gw\n"
                                            << "  min_interval: 50ms\n  heartbeat: 5s\n  diag_period: 1s\n"
                                            << "  deadband:\n    position_mm: 0.05\n"
                                            << "  reconnect_backoff:\n    initial: 100ms\n    max: 400ms\n";
        const auto config = fieldbridge::config::load_config_file(dir + "/config.yaml");
        asio::io_context io;
        auto logger = std::make_shared<spdlog::logger>("test", std::make_shared<spdlog::sinks::null_sink_mt>());
        fe::Engine engine(io, *config, fe::LogSink{});
        engine.start();
        fa::MqttComponent component(io, logger, [&] { return &engine; });
        fd::CompletionBarrier ready([] {});
        fd::StartContext start(config, ready);
        component.start(start);
        REQUIRE(component.bridge() != nullptr);
        Observer observer(broker.uri(), "sim/gw/#");

        // State, retained, with the decoded XEG fields once the gripper was polled.
        auto state = expect(io, observer, "sim/gw/g1/state", [](const json& j) {
            return j["online"] == true && j["fields"].contains("status") && j["fields"].contains("position_mm");
        });
        REQUIRE(state);
        CHECK((*state)["type"] == "hiwin-xeg");
        CHECK((*state)["raw"]["input"].contains("0x0301"));

        // A command moves the simulated gripper; the state follows it.
        std::size_t from = observer.count();
        observer.publish("sim/gw/g1/cmd", R"({"id":"r","op":"reset"})");
        auto result = expect(io, observer, "sim/gw/g1/cmd/result", [](const json& j) { return j["id"] == "r"; }, from);
        REQUIRE(result);
        CHECK((*result)["ok"] == true);
        // Homing: the state shows the gripper working, then idle again (homed).
        REQUIRE(expect(io, observer, "sim/gw/g1/state", [](const json& j) { return j["fields"]["status"] == "working"; },
                       from));
        from = observer.count();
        REQUIRE(expect(io, observer, "sim/gw/g1/state", [](const json& j) { return j["fields"]["status"] == "idle"; },
                       from));
        from = observer.count();
        observer.publish("sim/gw/g1/cmd", R"({"id":"m","op":"move","position_mm":12.5,"speed_mm_s":50})");
        result = expect(io, observer, "sim/gw/g1/cmd/result", [](const json& j) { return j["id"] == "m"; }, from);
        REQUIRE(result);
        INFO(result->dump());
        CHECK((*result)["ok"] == true);
        state = expect(io, observer, "sim/gw/g1/state", [](const json& j) {
            return j["fields"]["status"] == "positioned" && std::abs(j["fields"]["position_mm"].get<double>() - 12.5) < 0.01;
        }, from);
        CHECK(state);
        // An invalid command: error result, nothing on the line (the line's request
        // counter only moves with polls, so compare the command class).
        const auto commands_before = engine.lines()[0].worker->scheduler().stats(0)->of(fe::Priority::command).submitted;
        from = observer.count();
        observer.publish("sim/gw/g1/cmd", R"({"id":"bad","op":"move","position_mm":70,"speed_mm_s":1})");
        result = expect(io, observer, "sim/gw/g1/cmd/result", [](const json& j) { return j["id"] == "bad"; }, from);
        REQUIRE(result);
        CHECK((*result)["error"] == "rejected");
        CHECK(engine.lines()[0].worker->scheduler().stats(0)->of(fe::Priority::command).submitted == commands_before);

        // An injected alarm raises and clears.
        from = observer.count();
        CHECK(sim.control("device 1 alarm 5").rfind("ok", 0) == 0);
        REQUIRE(expect(io, observer, "sim/gw/g1/alarm", [](const json& j) {
            return j["event"] == "raised" && j["code"] == "move_alarm";
        }, from));
        CHECK(sim.control("device 1 clear").rfind("ok", 0) == 0);
        REQUIRE(expect(io, observer, "sim/gw/g1/alarm", [](const json& j) {
            return j["event"] == "cleared" && j["code"] == "move_alarm";
        }, from));

        // Broker outage: the device keeps answering requests (as Modbus TCP would ask).
        broker.stop();
        REQUIRE(run_until(io, [&] { return !component.bridge()->connected(); }));
        fe::DeviceAgent* agent = engine.find_device("g1");
        REQUIRE(agent != nullptr);
        int answered = 0;
        for (int i = 0; i < 20; ++i) {
            agent->request(fp::ReadRegistersRequest{fp::fc::read_input_registers, 0x0300, 2},
                           [&](const fp::Response& r) { answered += std::holds_alternative<fp::ReadRegistersResponse>(r); });
            REQUIRE(run_until(io, [&] { return answered == i + 1; }, 2s));
        }
        broker.start();
        REQUIRE(run_until(io, [&] { return component.bridge()->connected(); }));
        Observer again(broker.uri(), "sim/gw/#");
        CHECK(run_until(io, [&] {
            return again.wait_for("sim/gw/status", [](const Received& r) { return r.retained && r.payload == "online"; },
                                  0ms).has_value();
        }));
        CHECK(expect(io, again, "sim/gw/g1/state", [](const json& j) { return j["online"] == true; }));
        const auto diag = expect(io, again, "sim/gw/diag", [](const json& j) { return j.contains("lines"); });
        REQUIRE(diag);
        CHECK((*diag)["lines"][0]["name"] == "line-a");
        CHECK((*diag)["lines"][0]["devices"][0]["name"] == "g1");
        CHECK((*diag)["lines"][0]["requests"].get<std::uint64_t>() > 0);

        // Clean stop: offline.
        fd::CompletionBarrier finished([] {});
        fd::StopContext stop(finished);
        component.stop(stop);
        finished.arm();
        REQUIRE(run_until(io, [&] { return finished.complete(); }));
        engine.stop();
        io.restart();
        io.run_for(50ms);
        Observer late(broker.uri(), "sim/gw/status");
        CHECK(late.wait_for("sim/gw/status", [](const Received& r) { return r.payload == "offline"; }, 5s));
    }
    std::error_code ignored;
    std::filesystem::remove_all(dir, ignored);
}
