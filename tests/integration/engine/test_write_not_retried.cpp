// Issue 3, "a write that times out is not retried" (spec §3 rule 6): with the device's
// replies dropped, a write reaches the device exactly once and is answered 0x0B, while
// a read under the same fault goes on the wire 1 + read_retries times. The device did
// act on the write although its reply was lost: why a write must never be repeated.
#include <doctest/doctest.h>
#include <fmt/format.h>

#include "engine_harness.hpp"
#include "sim_process.hpp"

namespace fieldbridge::integration {
namespace {

using engine::OutcomeStatus;
using engine::Priority;
using engine::Table;
using test::SimProcess;

TEST_CASE("engine.write_retry: a write that times out is sent once and a read is retried") {
    SimProcess sim({"--bus", "{dir}/line-a:hiwin-xeg@2,excd203mb@3", "--wire-time", "--baud", "115200"});
    // The stepper is polled once (period 60 min): its frame count in the simulator moves
    // only with what this test sends. offline_after stays above the timeouts caused
    // here, so the device stays online and every attempt reaches the wire.
    constexpr unsigned read_retries = 2;
    EngineHarness h(fmt::format(R"(
gateway: {{ id: engine-it }}
lines:
  - name: line-a
    port: {}
    response_timeout: 50ms
    read_retries: {}
    offline_after: 10
    devices:
      - {{ name: xeg, type: hiwin-xeg, address: 2, unit_id: 1 }}
      - {{ name: excd, type: excd203mb, address: 3, unit_id: 2, max_age: 0ms, poll: {{ fast: 60min, slow: 60min }} }}
)",
                                sim.path("line-a"), read_retries));
    h.start();
    auto& excd = h.device("excd");
    REQUIRE(h.run_until([&] { return good_value(excd, Table::holding, 0x0001).has_value(); }, seconds{3}));
    const std::uint16_t before = *good_value(excd, Table::holding, 0x0001);
    const std::uint16_t written = before == 321 ? 322 : 321;  // hvs, 1-0x1388

    sim.command("fault line-a@3:drop");
    const auto frames_0 = sim.device_counter("line-a", 3, "frames");
    const auto write_answer = h.request(excd, write_register(0x0001, written));
    REQUIRE(write_answer.has_value());
    CHECK_MESSAGE(exception_of(*write_answer) == protocol::ExceptionCode::gateway_target_failed,
                  describe(write_answer));
    h.run_for(milliseconds{200});  // a retry would have gone by now
    const auto frames_1 = sim.device_counter("line-a", 3, "frames");
    CHECK(frames_1 - frames_0 == 1);
    const auto& commands = h.stats("excd").of(Priority::command);
    CHECK(commands.started == 1);
    CHECK(commands.retries == 0);
    CHECK(commands.outcome(OutcomeStatus::timeout) == 1);

    const auto read_answer = h.request(excd, read_holding(0x0001));
    REQUIRE(read_answer.has_value());
    CHECK_MESSAGE(exception_of(*read_answer) == protocol::ExceptionCode::gateway_target_failed, describe(read_answer));
    const auto frames_2 = sim.device_counter("line-a", 3, "frames");
    CHECK(frames_2 - frames_1 == 1 + read_retries);
    const auto& reads = h.stats("excd").of(Priority::on_demand);
    CHECK(reads.retries == read_retries);
    CHECK(reads.outcome(OutcomeStatus::timeout) == 1);
    CHECK(sim.device_counter("line-a", 3, "dropped") == 1 + 1 + read_retries);
    CHECK(excd.online());

    // The lost reply did not undo the write: the device acted once.
    sim.command("fault clear line-a@3");
    CHECK(h.read_register(excd, 0x0001) == written);
    h.stop();
    CHECK(sim.terminate() == 0);
}

}  // namespace
}  // namespace fieldbridge::integration
