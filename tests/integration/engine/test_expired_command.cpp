// Issue 3, "an expired command is rejected and never reaches the line" (spec §3 rule
// 9): a command that cannot start on the wire before its command_ttl is answered 0x0B
// and never sent. Here its device's delay_before_command (rule 11: extra silence before
// a command) is longer than its command_ttl while another device keeps the line busy,
// which the configuration allows (the two are independent keys).
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

TEST_CASE("engine.expiry: a command past its deadline is answered 0x0B and never sent") {
    SimProcess sim({"--bus", "{dir}/line-a:hiwin-xeg@2,excd203mb@3,excd203mb@4", "--wire-time", "--baud", "115200"});
    // The XEG polls every 50 ms, so the line is never silent for 300 ms. The two
    // steppers are polled once (period 60 min), so the simulator's frame counts of them
    // change only with what this test sends.
    EngineHarness h(fmt::format(R"(
gateway: {{ id: engine-it }}
lines:
  - name: line-a
    port: {}
    devices:
      - {{ name: xeg, type: hiwin-xeg, address: 2, unit_id: 1 }}
      - name: delayed
        type: excd203mb
        address: 3
        unit_id: 2
        max_age: 0ms
        command_ttl: 100ms
        delay_before_command: 300ms
        poll: {{ fast: 60min, slow: 60min }}
      - {{ name: control, type: excd203mb, address: 4, unit_id: 3, max_age: 0ms, command_ttl: 100ms,
           poll: {{ fast: 60min, slow: 60min }} }}
)",
                                sim.path("line-a")));
    h.start();
    auto& delayed = h.device("delayed");
    auto& control = h.device("control");
    auto& xeg = h.device("xeg");
    REQUIRE(h.run_until(
        [&] {
            return xeg.online() && good_value(delayed, Table::holding, 0x0001) &&
                   good_value(control, Table::holding, 0x0001);
        },
        seconds{3}));
    const std::uint16_t before = *good_value(delayed, Table::holding, 0x0001);
    const std::uint16_t written = before == 1234 ? 1235 : 1234;  // hvs, 1-0x1388
    h.run_for(milliseconds{200});

    const auto frames_before = sim.device_counter("line-a", 3, "frames");
    const auto expired_before = h.line("line-a").master().counters().expired;
    const auto answer = h.request(delayed, write_register(0x0001, written));
    REQUIRE(answer.has_value());
    CHECK_MESSAGE(exception_of(*answer) == protocol::ExceptionCode::gateway_target_failed, describe(answer));
    h.run_for(milliseconds{300});  // a late write would have reached the simulator by now
    CHECK(sim.device_counter("line-a", 3, "frames") == frames_before);
    CHECK(h.stats("delayed").of(Priority::command).outcome(OutcomeStatus::expired) == 1);
    CHECK(h.stats("delayed").of(Priority::command).outcome(OutcomeStatus::ok) == 0);
    CHECK(h.line("line-a").master().counters().expired == expired_before + 1);
    // The device still has its old value (a read is no command: no delay, it goes).
    CHECK(h.read_register(delayed, 0x0001) == before);
    CHECK(sim.device_counter("line-a", 3, "frames") == frames_before + 1);

    // The same write to a device without the delay goes, and the same checks see it.
    const auto control_frames = sim.device_counter("line-a", 4, "frames");
    const auto control_answer = h.request(control, write_register(0x0001, written));
    CHECK_MESSAGE((control_answer && std::holds_alternative<protocol::WriteSingleResponse>(*control_answer)),
                  describe(control_answer));
    CHECK(sim.device_counter("line-a", 4, "frames") == control_frames + 1);
    CHECK(h.read_register(control, 0x0001) == written);
    h.stop();
    CHECK(sim.terminate() == 0);
}

}  // namespace
}  // namespace fieldbridge::integration
