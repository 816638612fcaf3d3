#include <doctest/doctest.h>

#include "fault_plan.hpp"
#include "sim_error.hpp"

namespace fieldbridge::sim::runtime {

using namespace std::chrono_literals;

TEST_CASE("fault specs parse in colon and blank form") {
    const auto drop = parse_fault_spec("line-a:drop:0.01");
    CHECK(drop.bus == "line-a");
    CHECK_FALSE(drop.address);
    CHECK(drop.kind == FaultKind::drop);
    CHECK(drop.trigger.mode == FaultTrigger::Mode::probability);
    CHECK(drop.trigger.probability == doctest::Approx(0.01));

    const auto delay = parse_fault_spec("line-a@2 delay 50 next=3");
    REQUIRE(delay.address);
    CHECK(*delay.address == 2);
    CHECK(delay.kind == FaultKind::delay);
    CHECK(delay.duration == 50ms);
    CHECK(delay.trigger.mode == FaultTrigger::Mode::next);
    CHECK(delay.trigger.remaining == 3);

    const auto unplug = parse_fault_spec("line-b:unplug:1.5s");
    CHECK(unplug.kind == FaultKind::unplug);
    CHECK(unplug.duration == 1500ms);

    CHECK(parse_fault_spec("line-a:echo").trigger.mode == FaultTrigger::Mode::always);
    CHECK(parse_fault_spec("line-a:echo:off").trigger.mode == FaultTrigger::Mode::off);
    CHECK(parse_fault_spec("line-a@3:corrupt-crc:1").trigger.mode == FaultTrigger::Mode::always);
}

TEST_CASE("bad fault specs say what is wrong") {
    CHECK_THROWS_AS((void)parse_fault_spec("line-a"), SimError);
    CHECK_THROWS_AS((void)parse_fault_spec("line-a:explode"), SimError);
    CHECK_THROWS_AS((void)parse_fault_spec("line-a:delay"), SimError);
    CHECK_THROWS_AS((void)parse_fault_spec("line-a:drop:1.5"), SimError);
    CHECK_THROWS_AS((void)parse_fault_spec("line-a:drop:0"), SimError);
    CHECK_THROWS_AS((void)parse_fault_spec("line-a:drop:next=0"), SimError);
    CHECK_THROWS_AS((void)parse_fault_spec("line-a@300:drop"), SimError);
    CHECK_THROWS_AS((void)parse_fault_spec("line-a@2:echo"), SimError);
    CHECK_THROWS_AS((void)parse_fault_spec("line-a@2:dead:0.5"), SimError);
    CHECK_THROWS_AS((void)parse_fault_spec("line-a:drop:always:extra"), SimError);
    try {
        (void)parse_fault_spec("line-a:explode");
    } catch (const SimError& e) {
        CHECK(std::string(e.what()).find("explode") != std::string::npos);
    }
}

TEST_CASE("next=N hits exactly N replies of the addressed device") {
    FaultPlan plan(1);
    plan.set(parse_fault_spec("line-a@2:drop:next=2"));
    CHECK_FALSE(plan.decide_reply(3).drop);
    CHECK(plan.decide_reply(2).drop);
    CHECK(plan.decide_reply(2).drop);
    CHECK_FALSE(plan.decide_reply(2).drop);
    CHECK(plan.empty());
}

TEST_CASE("probabilities are reproducible with the same seed and roughly right") {
    FaultPlan a(7);
    FaultPlan b(7);
    a.set(parse_fault_spec("line-a:corrupt-crc:0.25"));
    b.set(parse_fault_spec("line-a:corrupt-crc:0.25"));
    int hits = 0;
    for (int i = 0; i < 4000; ++i) {
        const bool x = a.decide_reply(1).corrupt_crc;
        CHECK(x == b.decide_reply(1).corrupt_crc);
        hits += x ? 1 : 0;
    }
    CHECK(hits > 850);
    CHECK(hits < 1150);
}

TEST_CASE("rules combine, replace and clear") {
    FaultPlan plan(3);
    plan.set(parse_fault_spec("line-a:delay:10"));
    plan.set(parse_fault_spec("line-a@2:delay:5"));
    plan.set(parse_fault_spec("line-a@2:truncate"));
    auto faults = plan.decide_reply(2);
    CHECK(faults.delay == 15ms);
    CHECK(faults.truncate);
    plan.set(parse_fault_spec("line-a:delay:20"));  // replaces the bus-wide delay
    CHECK(plan.decide_reply(2).delay == 25ms);
    plan.clear(std::uint8_t{2});
    CHECK(plan.decide_reply(2).delay == 20ms);
    CHECK_FALSE(plan.decide_reply(2).truncate);
    plan.set(parse_fault_spec("line-a:delay:off"));
    CHECK(plan.empty());
}

TEST_CASE("echo is a bus rule; garbage never contains '>'") {
    FaultPlan plan(9);
    CHECK_FALSE(plan.decide_echo());
    plan.set(parse_fault_spec("line-a:echo:next=1"));
    CHECK(plan.decide_echo());
    CHECK_FALSE(plan.decide_echo());
    for (int i = 0; i < 200; ++i) {
        const auto noise = plan.random_garbage();
        CHECK(noise.size() >= 1);
        CHECK(noise.size() <= 8);
        for (const auto b : noise) {
            CHECK(b != '>');
        }
    }
}

}  // namespace fieldbridge::sim::runtime
