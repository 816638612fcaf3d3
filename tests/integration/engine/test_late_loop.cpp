// A reply that arrived in time is not judged a timeout when the loop runs late. The
// daemon shares one io_context between the lines, the Modbus TCP server and MQTT: a
// slow handler holds every line up. Here one handler takes longer than the response
// timeout while a write is on the wire, and submits a read meanwhile (so the worker's
// posted drive runs before the port's readiness handler). The device's answer is in
// the pty by then: the write must be reported done, not 0x0B (found by these tests;
// fixed in gateway/engine/line_worker.cpp, drive()).
#include <doctest/doctest.h>
#include <fmt/format.h>

#include <asio/post.hpp>
#include <thread>

#include "engine_harness.hpp"
#include "sim_process.hpp"

namespace fieldbridge::integration {
namespace {

using engine::Table;
using test::SimProcess;

TEST_CASE("engine.late_loop: a reply in the buffer wins over its timeout after a slow handler") {
    SimProcess sim({"--bus", "{dir}/line-a:excd203mb@3", "--wire-time", "--baud", "115200"});
    EngineHarness h(fmt::format(R"(
gateway: {{ id: engine-it }}
lines:
  - name: line-a
    port: {}
    response_timeout: 50ms
    devices:
      - {{ name: excd, type: excd203mb, address: 3, unit_id: 1, max_age: 0ms, poll: {{ fast: 60min, slow: 60min }} }}
)",
                                sim.path("line-a")));
    h.start();
    auto& excd = h.device("excd");
    REQUIRE(h.run_until([&] { return good_value(excd, Table::holding, 0x0001).has_value(); }, seconds{3}));
    h.run_for(milliseconds{50});
    const std::uint16_t written = *good_value(excd, Table::holding, 0x0001) == 300 ? 301 : 300;
    const auto& counters = h.line("line-a").master().counters();
    const auto requests_before = counters.requests;
    const auto timeouts_before = counters.timeouts;

    std::optional<protocol::Response> write_answer;
    std::optional<protocol::Response> read_answer;
    excd.request(write_register(0x0001, written), [&](const protocol::Response& r) { write_answer = r; });
    // One handler at a time until the write is on the wire (bounded).
    const auto deadline = engine::Clock::now() + seconds{2};
    while (counters.requests == requests_before && engine::Clock::now() < deadline) {
        h.io().run_one_for(milliseconds{10});
    }
    REQUIRE(counters.requests == requests_before + 1);
    asio::post(h.io(), [&] {
        // A slow handler on the shared loop: longer than response_timeout (50 ms); the
        // simulator answers within 3 ms of the request. The sleep is the thing under
        // test (a late loop), not orchestration.
        std::this_thread::sleep_for(milliseconds{120});
        excd.request(read_holding(0x0001), [&](const protocol::Response& r) { read_answer = r; });
    });
    REQUIRE(h.run_until([&] { return write_answer && read_answer; }, seconds{2}));
    CHECK_MESSAGE(std::holds_alternative<protocol::WriteSingleResponse>(*write_answer), describe(write_answer));
    CHECK(registers_of(*read_answer) == std::vector<std::uint16_t>{written});
    CHECK(counters.timeouts == timeouts_before);
    CHECK(sim.device_counter("line-a", 3, "replies") == sim.device_counter("line-a", 3, "frames"));
    h.stop();
    CHECK(sim.terminate() == 0);
}

}  // namespace
}  // namespace fieldbridge::integration
