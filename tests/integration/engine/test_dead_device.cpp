// Issue 3, "a dead device among live ones costs the live ones at most 10 % of their
// poll rate" (spec §3 rules 7, 10): the same three live devices polled with and without
// a fourth configured at an address nobody answers, at a realistic wire speed. The
// rates are measured in the same process one after the other, so machine load affects
// both; only their ratio is checked.
#include <doctest/doctest.h>
#include <fmt/format.h>

#include <array>

#include "engine_harness.hpp"
#include "sim_process.hpp"

namespace fieldbridge::integration {
namespace {

using engine::OutcomeStatus;
using engine::Priority;
using test::SimProcess;

constexpr std::array<const char*, 3> live{"xeg", "excd", "ascii"};
constexpr auto warm_up = seconds{1};
constexpr auto window = seconds{3};

std::string cell_yaml(const SimProcess& sim, bool with_dead_device) {
    return fmt::format(R"(
gateway: {{ id: engine-it }}
lines:
  - name: line-a
    port: {}
    devices:
      - {{ name: xeg, type: hiwin-xeg, address: 2, unit_id: 1 }}
      - {{ name: excd, type: excd203mb, address: 3, unit_id: 2 }}
      - {{ name: ascii, type: wtec-ascii, address: 5, unit_id: 3, stroke: 20000 }}
{})",
                       sim.path("line-a"),
                       with_dead_device ? "      - { name: ghost, type: hiwin-xeg, address: 7, unit_id: 4 }\n" : "");
}

std::uint64_t live_polls_ok(const EngineHarness& h, std::string_view name) {
    return h.stats(name).of(Priority::poll).outcome(OutcomeStatus::ok);
}

/// Poll completions per second of each live device over `window`, after `warm_up`.
std::array<double, live.size()> measure(const SimProcess& sim, bool with_dead_device) {
    EngineHarness h(cell_yaml(sim, with_dead_device));
    h.start();
    const auto ready = [&] {
        for (const char* name : live) {
            if (!h.device(name).online() || live_polls_ok(h, name) == 0) return false;
        }
        return !with_dead_device || !h.device("ghost").online();
    };
    // The ghost goes offline after offline_after (3) timeouts of 100 ms.
    REQUIRE_MESSAGE(h.run_until(ready, seconds{5}), h.engine().status());
    h.run_for(warm_up);
    std::array<std::uint64_t, live.size()> start{};
    for (std::size_t i = 0; i < live.size(); ++i) start[i] = live_polls_ok(h, live[i]);
    const auto t0 = engine::Clock::now();
    h.run_for(window);
    const double elapsed = std::chrono::duration<double>(engine::Clock::now() - t0).count();
    std::array<double, live.size()> rates{};
    for (std::size_t i = 0; i < live.size(); ++i) {
        rates[i] = static_cast<double>(live_polls_ok(h, live[i]) - start[i]) / elapsed;
        CHECK(h.device(live[i]).online());
    }
    if (with_dead_device) {
        CHECK_FALSE(h.device("ghost").online());
        const auto& ghost = h.stats("ghost");
        CHECK(ghost.went_offline >= 1);
        CHECK(ghost.came_online == 0);
    }
    return rates;
}

TEST_CASE("engine.dead_device: a dead device costs the live ones at most 10 % of their poll rate") {
    SimProcess sim({"--bus", "{dir}/line-a:hiwin-xeg@2,excd203mb@3,wtec-ascii@5", "--wire-time", "--baud", "115200"});
    const auto alone = measure(sim, false);
    const auto with_dead = measure(sim, true);
    double sum_alone = 0;
    double sum_with_dead = 0;
    for (std::size_t i = 0; i < live.size(); ++i) {
        MESSAGE(std::string(live[i]), ": ", alone[i], " polls/s alone, ", with_dead[i], " with a dead device");
        REQUIRE(alone[i] > 0);
        sum_alone += alone[i];
        sum_with_dead += with_dead[i];
    }
    CHECK(sum_with_dead / sum_alone >= 0.90);
    CHECK(sim.bus_counter("line-a", "unanswered") > 0);  // the ghost's frames were on the wire
    CHECK(sim.terminate() == 0);
}

}  // namespace
}  // namespace fieldbridge::integration
