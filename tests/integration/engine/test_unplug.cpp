// Issue 3, "the port vanishing and returning is survived": the simulator pulls the
// bus's pty away (a USB adapter unplugged) and brings it back on a new pty behind the
// same link. The line goes down (its devices offline, requests answered 0x0B), the
// worker reopens the port with back-off, and polling fills the image again.
#include <doctest/doctest.h>
#include <fmt/format.h>

#include "engine_harness.hpp"
#include "sim_process.hpp"

namespace fieldbridge::integration {
namespace {

using engine::OutcomeStatus;
using engine::Priority;
using engine::Quality;
using engine::Table;
using test::SimProcess;

TEST_CASE("engine.unplug: the line goes down with its port and comes back with it") {
    SimProcess sim({"--bus", "{dir}/line-a:hiwin-xeg@2,excd203mb@3", "--bus", "{dir}/line-b:wtec-rtu@1",
                    "--wire-time", "--baud", "115200"});
    EngineHarness h(fmt::format(R"(
gateway: {{ id: engine-it }}
lines:
  - name: line-a
    port: {}
    offline_backoff: {{ initial: 100ms, max: 400ms }}
    devices:
      - {{ name: xeg, type: hiwin-xeg, address: 2, unit_id: 1, max_age: 0ms }}
      - {{ name: excd, type: excd203mb, address: 3, unit_id: 2 }}
  - name: line-b
    port: {}
    devices:
      - {{ name: rtu, type: wtec-rtu, address: 1, unit_id: 3 }}
)",
                                sim.path("line-a"), sim.path("line-b")));
    h.start();
    auto& worker = h.line("line-a");
    auto& xeg = h.device("xeg");
    auto& excd = h.device("excd");
    auto& rtu = h.device("rtu");
    const auto image_good = [&] {
        return xeg.online() && excd.online() && good_value(xeg, Table::input, 0x0301) &&
               good_value(excd, Table::holding, 0x0205);
    };
    REQUIRE(h.run_until(image_good, seconds{3}));
    CHECK(worker.reopens() == 0);

    sim.command("fault line-a:unplug:1500");
    REQUIRE_MESSAGE(h.run_until([&] { return !worker.line_up(); }, seconds{2}), "the worker did not see the port go");
    CHECK_FALSE(xeg.online());
    CHECK_FALSE(excd.online());
    CHECK(xeg.image().quality(Table::input, 0x0301) == Quality::offline);
    CHECK(excd.image().quality(Table::holding, 0x0205) == Quality::offline);
    // A client is told at once that the path is gone (spec §8: line_down -> 0x0A).
    const auto read_answer = h.request(xeg, read_input(0x0301));
    CHECK_MESSAGE((read_answer && exception_of(*read_answer) == protocol::ExceptionCode::gateway_path_unavailable),
                  describe(read_answer));
    const auto write_answer = h.request(excd, write_register(0x0001, 100));
    CHECK_MESSAGE((write_answer && exception_of(*write_answer) == protocol::ExceptionCode::gateway_path_unavailable),
                  describe(write_answer));
    CHECK(h.stats("excd").of(Priority::command).outcome(OutcomeStatus::line_down) == 1);
    // The other line does not care.
    CHECK(h.line("line-b").line_up());
    CHECK(rtu.online());

    // The port comes back after 1.5 s; the worker retries every 100-400 ms.
    REQUIRE_MESSAGE(h.run_until([&] { return worker.line_up(); }, seconds{4}), "the worker did not reopen the port");
    CHECK(worker.reopens() >= 1);
    const auto polls_back = h.stats("xeg").of(Priority::poll).outcome(OutcomeStatus::ok);
    REQUIRE(h.run_until(
        [&] { return image_good() && h.stats("xeg").of(Priority::poll).outcome(OutcomeStatus::ok) > polls_back + 5; },
        seconds{3}));
    const auto read_again = h.request(xeg, read_input(0x0301));
    CHECK_MESSAGE((read_again && registers_of(*read_again).size() == 1), describe(read_again));
    CHECK(sim.bus_counter("line-a", "unplugs") == 1);
    CHECK(h.line("line-b").reopens() == 0);
    h.stop();
    CHECK(sim.terminate() == 0);
}

}  // namespace
}  // namespace fieldbridge::integration
