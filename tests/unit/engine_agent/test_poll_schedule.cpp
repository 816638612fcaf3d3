// PollSchedule: when each poll item is due (spec §3 rules 3, 5, 8), on a fake clock.
#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <vector>

#include "engine/poll_schedule.hpp"

namespace {

namespace fe = fieldbridge::engine;
using namespace std::chrono_literals;
using Ids = std::vector<std::uint32_t>;

fe::TimePoint t0() { return fe::TimePoint{} + std::chrono::hours{1}; }

fe::PollItem item(fe::PollClass poll_class, fe::Duration period, bool motion, std::uint16_t address,
                  std::uint16_t units = 1) {
    fe::PollItem i;
    i.poll_class = poll_class;
    i.period = period;
    i.motion = motion;
    const fe::RegisterSpan span{fe::Table::holding, address, units};
    i.payload = fe::read_payload(span);
    i.fills = {span};
    for (std::uint16_t u = 0; u < units; ++u) {
        i.units.push_back({fe::Table::holding, static_cast<std::uint16_t>(address + u), 1});
    }
    return i;
}

/// 1: fast 10 ms (motion), 2: slow 100 ms, 3: startup.
fe::PollSchedule schedule() {
    fe::PollSchedule s{fe::PollPlan{{item(fe::PollClass::fast, 10ms, true, 0x10, 4),
                                     item(fe::PollClass::slow, 100ms, false, 0x20),
                                     item(fe::PollClass::startup, {}, false, 0x30)}},
                       2ms, 50ms};
    s.restart(t0());
    return s;
}

}  // namespace

TEST_CASE("poll schedule: everything is due at the start, and never twice while outstanding") {
    auto s = schedule();
    CHECK(s.next_due() == t0());
    CHECK(s.take_due(t0()) == Ids{1, 2, 3});
    CHECK(s.outstanding(1));
    CHECK(s.take_due(t0() + 1s).empty());
    CHECK_FALSE(s.next_due());
    CHECK(s.last_taken(1) == t0());
}

TEST_CASE("poll schedule: periodic items keep their cadence; an outstanding item is due when it finishes") {
    auto s = schedule();
    (void)s.take_due(t0());
    s.finished(1, true, t0() + 3ms);
    s.finished(2, true, t0() + 3ms);
    CHECK(s.next_due() == t0() + 10ms);
    CHECK(s.take_due(t0() + 9ms).empty());
    CHECK(s.take_due(t0() + 11ms) == Ids{1});  // a late timer: the slot stays at 10 ms
    s.finished(1, true, t0() + 12ms);
    CHECK(s.next_due() == t0() + 20ms);
    // The item is still outstanding when its slot passes: due as soon as it is back.
    CHECK(s.take_due(t0() + 20ms) == Ids{1});
    CHECK(s.take_due(t0() + 30ms).empty());
    s.finished(1, false, t0() + 35ms);
    CHECK(s.next_due() == t0() + 30ms);
    CHECK(s.take_due(t0() + 35ms) == Ids{1});
    s.finished(1, true, t0() + 36ms);
    CHECK(s.next_due() == t0() + 40ms);
}

TEST_CASE("poll schedule: an item a whole period late counts from now instead of bursting") {
    auto s = schedule();
    (void)s.take_due(t0());
    s.finished(1, true, t0() + 1ms);
    CHECK(s.take_due(t0() + 45ms) == Ids{1});  // due at 10 ms, 35 ms late
    s.finished(1, true, t0() + 46ms);
    CHECK(s.next_due() == t0() + 55ms);
}

TEST_CASE("poll schedule: startup items until answered, retried after a failure, again after restart") {
    auto s = schedule();
    (void)s.take_due(t0());
    s.finished(1, true, t0());
    s.finished(2, true, t0());
    s.finished(3, false, t0() + 5ms);
    CHECK(s.take_due(t0() + 54ms) == Ids{1});
    CHECK(s.take_due(t0() + 55ms) == Ids{3});
    s.finished(3, true, t0() + 56ms);
    s.finished(1, true, t0() + 56ms);
    // Done: only the periodic items from now on.
    for (auto t = t0() + 60ms; t < t0() + 1s; t += 10ms) {
        const Ids due = s.take_due(t);
        CHECK(std::find(due.begin(), due.end(), 3U) == due.end());
        for (const auto id : due) s.finished(id, true, t);
    }
    s.restart(t0() + 2s);
    CHECK(s.take_due(t0() + 2s) == Ids{1, 2, 3});
}

TEST_CASE("poll schedule: motion items use the motion period while motion is on") {
    auto s = schedule();
    const fe::PollItem& fast = *s.find(1);
    const fe::PollItem& slow = *s.find(2);
    CHECK(s.period_of(fast) == fe::Duration{10ms});
    s.set_motion(true);
    CHECK(s.period_of(fast) == fe::Duration{2ms});
    CHECK(s.period_of(slow) == fe::Duration{100ms});
    CHECK(s.period_of(*s.find(3)) == fe::Duration{});
    (void)s.take_due(t0());
    s.finished(1, true, t0() + 1ms);
    CHECK(s.next_due() == t0() + 2ms);
    s.set_motion(false);
    CHECK(s.next_due() == t0() + 10ms);
}

TEST_CASE("poll schedule: a rejected block is replaced by halves due at once; a single unit is dropped") {
    auto s = schedule();
    (void)s.take_due(t0());
    const auto halves = s.reject(1, t0() + 1ms);
    REQUIRE(halves.size() == 2);
    CHECK(s.find(1) == nullptr);
    CHECK(s.plan().items().size() == 4);
    CHECK(s.take_due(t0() + 1ms) == Ids{halves[0].id, halves[1].id});
    CHECK(s.reject(2, t0() + 2ms).empty());  // one unit: dropped
    CHECK(s.plan().items().size() == 3);
    CHECK(s.plan().rejected().size() == 1);
}
