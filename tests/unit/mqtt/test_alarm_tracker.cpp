// Alarm raise / clear diffing, communication loss with hysteresis, device notices.
#include <doctest/doctest.h>

#include "northbound/mqtt/alarm_tracker.hpp"

namespace {

namespace fe = fieldbridge::engine;
namespace fm = fieldbridge::northbound::mqtt;
using namespace std::chrono_literals;

const fe::Alarm move_alarm{"move_alarm", "move alarm", fe::Severity::error, "input 0x0301"};
const fe::Alarm alm1{"alm1", "ALM1", fe::Severity::error, "discrete input 0x0013"};

fm::AlarmTracker tracker() { return fm::AlarmTracker(fm::AlarmSettings{5s, 60s}); }

}  // namespace

TEST_CASE("alarms: raised once, kept while present, cleared when gone") {
    auto t = tracker();
    const fe::TimePoint t0{};
    CHECK(t.update({}, true, t0).empty());
    auto events = t.update({move_alarm}, true, t0 + 1s);
    REQUIRE(events.size() == 1);
    CHECK(events[0] == fm::AlarmEvent{fm::AlarmTransition::raised, move_alarm, t0 + 1s});
    CHECK(t.update({move_alarm}, true, t0 + 2s).empty());
    events = t.update({alm1}, true, t0 + 3s);
    REQUIRE(events.size() == 2);
    CHECK(events[0].transition == fm::AlarmTransition::cleared);
    CHECK(events[0].alarm == move_alarm);
    CHECK(events[1].transition == fm::AlarmTransition::raised);
    CHECK(events[1].alarm == alm1);
    REQUIRE(t.active().size() == 1);
    CHECK(t.active()[0].since == t0 + 3s);
    events = t.update({}, true, t0 + 4s);
    REQUIRE(events.size() == 1);
    CHECK(events[0].transition == fm::AlarmTransition::cleared);
    CHECK(t.active().empty());
}

TEST_CASE("alarms: a device not yet online at start-up gets a grace before comm_loss") {
    auto t = tracker();
    const fe::TimePoint t0{};
    CHECK(t.update({}, false, t0).empty());
    CHECK(t.next_deadline() == t0 + 5s);
    CHECK(t.update({}, false, t0 + 4s).empty());
    auto events = t.update({}, false, t0 + 5s);
    REQUIRE(events.size() == 1);
    CHECK(events[0].alarm.code == fm::comm_loss_code);

    // Online within the grace: never raised.
    auto u = tracker();
    CHECK(u.update({}, false, t0).empty());
    CHECK(u.update({}, true, t0 + 1s).empty());
    CHECK_FALSE(u.next_deadline());
    CHECK(u.update({}, true, t0 + 10s).empty());
}

TEST_CASE("alarms: communication loss is raised at once and cleared only after the device stayed online") {
    auto t = tracker();
    const fe::TimePoint t0{};
    CHECK(t.update({}, true, t0 - 1s).empty());
    auto events = t.update({}, false, t0);
    REQUIRE(events.size() == 1);
    CHECK(events[0].alarm.code == fm::comm_loss_code);
    CHECK(events[0].alarm.severity == fe::Severity::critical);
    // Back online, then flapping: no clear until 5 s online in a row.
    CHECK(t.update({}, true, t0 + 1s).empty());
    CHECK(t.next_deadline() == t0 + 6s);
    CHECK(t.update({}, true, t0 + 4s).empty());
    CHECK(t.update({}, false, t0 + 5s).empty());
    CHECK_FALSE(t.next_deadline());
    CHECK(t.update({}, true, t0 + 6s).empty());
    CHECK(t.update({}, true, t0 + 10s).empty());
    events = t.update({}, true, t0 + 11s);
    REQUIRE(events.size() == 1);
    CHECK(events[0].transition == fm::AlarmTransition::cleared);
    CHECK(events[0].alarm.code == fm::comm_loss_code);
    CHECK(t.active().empty());
}

TEST_CASE("alarms: a device notice stays active for its hold, a new one renews it, code 0 clears it") {
    auto t = tracker();
    const fe::TimePoint t0{};
    t.notice(fe::DeviceNotice{0x07, "incorrect move"}, t0);
    auto events = t.update({}, true, t0);
    REQUIRE(events.size() == 1);
    CHECK(events[0].alarm.code == fm::exception_status_code);
    CHECK(events[0].alarm.text == "incorrect move");
    CHECK(events[0].alarm.source == "exception status 0x07");
    CHECK(t.next_deadline() == t0 + 60s);
    CHECK(t.update({}, true, t0 + 30s).empty());
    events = t.update({}, true, t0 + 60s);
    REQUIRE(events.size() == 1);
    CHECK(events[0].transition == fm::AlarmTransition::cleared);

    t.notice(fe::DeviceNotice{0x02, "emergency stop"}, t0 + 70s);
    CHECK(t.update({}, true, t0 + 70s).size() == 1);
    t.notice(fe::DeviceNotice{0x02, "emergency stop"}, t0 + 80s);
    events = t.update({}, true, t0 + 80s);
    REQUIRE(events.size() == 2);  // the repeated notice is a new event
    CHECK(events[1].transition == fm::AlarmTransition::raised);
    t.notice(fe::DeviceNotice{0x00, "no error"}, t0 + 81s);
    events = t.update({}, true, t0 + 81s);
    REQUIRE(events.size() == 1);
    CHECK(events[0].transition == fm::AlarmTransition::cleared);
}
