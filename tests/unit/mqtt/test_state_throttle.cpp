// When state is published: change, deadband, min interval, heartbeat (spec §6).
#include <doctest/doctest.h>

#include "northbound/mqtt/state_throttle.hpp"

namespace {

namespace fe = fieldbridge::engine;
namespace fm = fieldbridge::northbound::mqtt;
using namespace std::chrono_literals;

fm::SourceState with(double position, std::string status = "idle", bool online = true) {
    fm::SourceState s;
    s.online = online;
    s.quality = online ? fe::Quality::good : fe::Quality::offline;
    s.decoded.fields = {fe::Field{"status", status, ""}, fe::Field{"position_mm", position, "mm"}};
    return s;
}

fm::ThrottleSettings throttle_settings() {
    fm::ThrottleSettings s;
    s.min_interval = 200ms;
    s.heartbeat = 10s;
    s.deadband = {{"position_mm", 0.05}};
    return s;
}

}  // namespace

TEST_CASE("throttle: the first state is due at once; nothing new is not due until the heartbeat") {
    fm::StateThrottle t(throttle_settings());
    const fe::TimePoint t0{};
    CHECK(t.due(with(1.0), t0));
    t.published(with(1.0), t0);
    CHECK_FALSE(t.due(with(1.0), t0 + 5s));
    CHECK(t.next_check(with(1.0)) == t0 + 10s);
    CHECK(t.due(with(1.0), t0 + 10s));
}

TEST_CASE("throttle: a change below the deadband is not published; drift adds up against the last published value") {
    fm::StateThrottle t(throttle_settings());
    const fe::TimePoint t0{};
    t.published(with(1.0), t0);
    CHECK_FALSE(t.due(with(1.03), t0 + 1s));
    CHECK_FALSE(t.due(with(0.96), t0 + 1s));
    CHECK(t.due(with(1.05), t0 + 1s));
    CHECK(t.due(with(0.9), t0 + 1s));
    // A field without a deadband: any change.
    CHECK(t.due(with(1.0, "working"), t0 + 1s));
    // Online and quality always count.
    CHECK(t.due(with(1.0, "idle", false), t0 + 1s));
}

TEST_CASE("throttle: a list field (R6 axes_deg) moves when one of its numbers moves past the deadband") {
    auto axes = [](std::vector<double> values) {
        fm::SourceState s;
        s.online = true;
        s.quality = fe::Quality::good;
        s.decoded.fields = {fe::Field{"axes_deg", std::move(values), "deg"}};
        return s;
    };
    auto config = throttle_settings();
    config.deadband = {{"axes_deg", 0.1}};
    fm::StateThrottle t(config);
    const fe::TimePoint t0{};
    t.published(axes({10.0, -1.0}), t0);
    CHECK_FALSE(t.due(axes({10.05, -1.05}), t0 + 1s));
    CHECK(t.due(axes({10.0, -1.2}), t0 + 1s));
    CHECK(t.due(axes({10.0, -1.0, 0.0}), t0 + 1s));  // another axis count: a change
    // Without a deadband any change counts.
    fm::StateThrottle plain(throttle_settings());
    plain.published(axes({10.0, -1.0}), t0);
    CHECK(plain.due(axes({10.001, -1.0}), t0 + 1s));
}

TEST_CASE("throttle: a change waits for the minimum interval after the previous publication") {
    fm::StateThrottle t(throttle_settings());
    const fe::TimePoint t0{};
    t.published(with(1.0), t0);
    CHECK_FALSE(t.due(with(2.0), t0 + 100ms));
    CHECK(t.next_check(with(2.0)) == t0 + 200ms);
    CHECK(t.due(with(2.0), t0 + 200ms));
    t.published(with(2.0), t0 + 200ms);
    CHECK(t.next_check(with(2.0)) == t0 + 200ms + 10s);
}

TEST_CASE("throttle: reset makes the next state due at once (reconnect)") {
    fm::StateThrottle t(throttle_settings());
    t.published(with(1.0), fe::TimePoint{});
    CHECK_FALSE(t.due(with(1.0), fe::TimePoint{} + 1s));
    t.reset();
    CHECK(t.due(with(1.0), fe::TimePoint{} + 1s));
    CHECK_FALSE(t.next_check(with(1.0)));
}

TEST_CASE("throttle: without decoded fields the raw registers are the state") {
    fm::SourceState a;
    a.online = true;
    a.quality = fe::Quality::good;
    a.raw = {fm::RawRegister{fe::Table::holding, 0x10, 1}};
    fm::SourceState b = a;
    CHECK_FALSE(fm::state_differs(a, b, {}));
    b.raw[0].value = 2;
    CHECK(fm::state_differs(a, b, {}));
    // With decoded fields, raw registers alone do not count (the deadband would be moot).
    a.decoded.fields = {fe::Field{"x", std::int64_t{1}, ""}};
    b.decoded.fields = a.decoded.fields;
    CHECK_FALSE(fm::state_differs(a, b, {}));
}
