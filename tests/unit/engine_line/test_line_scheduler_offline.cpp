// LineScheduler: offline devices (rules 7 and 10): N consecutive timeouts, one held
// request, probe back-off, live devices first, back online on any valid reply.
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "line_test_support.hpp"

namespace {

using namespace line_test;
using fe::OutcomeStatus;

struct Health {
    std::vector<std::pair<fe::DeviceIndex, bool>> events;
    std::vector<TimePoint> times;
};

fe::DeviceLimits dead_device_limits() {
    fe::DeviceLimits limits;
    limits.read_retries = 0;
    limits.offline_after = 3;
    limits.backoff_initial = 1s;
    limits.backoff_max = 5s;
    return limits;
}

struct Fixture {
    Scheduler s{fe::SchedulerConfig{"A"}};
    Recorder r;
    Health health;
    int count = 0;

    explicit Fixture(fe::DeviceLimits limits = dead_device_limits()) {
        s.add_device(0, limits);
        s.add_device(1, limits);
        s.set_health_callback([this](fe::DeviceIndex device, bool online, TimePoint now) {
            health.events.emplace_back(device, online);
            health.times.push_back(now);
        });
    }
    std::string poll(fe::DeviceIndex device, TimePoint now, Priority priority = Priority::poll) {
        const std::string tag = "d" + std::to_string(device) + "-" + std::to_string(count++);
        s.submit(tagged(read_tx(device, static_cast<std::uint8_t>(device + 1), priority), r, tag), now);
        return tag;
    }
    /// Next transaction must be for @p device; completes it as @p status.
    void run(fe::DeviceIndex device, TimePoint now, OutcomeStatus status) {
        auto t = s.next(now);
        REQUIRE(t.has_value());
        REQUIRE(t->device == device);
        ++t->attempts;
        fe::Outcome outcome;
        outcome.status = status;
        outcome.finished = now;
        outcome.attempts = t->attempts;
        s.finished(std::move(*t), outcome, now);
    }
};

TEST_CASE("offline: N consecutive timeouts take a device offline, once") {
    Fixture f;
    TimePoint now = t0;
    for (int i = 0; i < 2; ++i) {
        f.poll(0, now);
        f.run(0, now += 100ms, OutcomeStatus::timeout);
        CHECK(f.s.online(0));
    }
    f.poll(0, now);
    f.run(0, now += 100ms, OutcomeStatus::timeout);
    CHECK_FALSE(f.s.online(0));
    REQUIRE(f.health.events.size() == 1);
    CHECK(f.health.events[0] == std::make_pair(fe::DeviceIndex{0}, false));
    CHECK(f.health.times[0] == t0 + 300ms);
    CHECK(f.s.stats(0)->went_offline == 1);
    CHECK(f.s.probe_due(0) == t0 + 300ms + 1s);
    CHECK(f.s.online(1));
    CHECK_FALSE(f.s.probe_due(1).has_value());
}

TEST_CASE("offline: a valid reply in between resets the count") {
    Fixture f;
    TimePoint now = t0;
    for (const auto status : {OutcomeStatus::timeout, OutcomeStatus::timeout, OutcomeStatus::ok,
                              OutcomeStatus::timeout, OutcomeStatus::timeout}) {
        f.poll(0, now);
        f.run(0, now += 10ms, status);
    }
    CHECK(f.s.online(0));
    CHECK(f.health.events.empty());
}

TEST_CASE("offline: a reply that does not fit the request is an answer: it resets the count and brings a device back") {
    Fixture f;
    TimePoint now = t0;
    for (const auto status : {OutcomeStatus::timeout, OutcomeStatus::timeout, OutcomeStatus::bad_reply,
                              OutcomeStatus::timeout, OutcomeStatus::timeout}) {
        f.poll(0, now);
        f.run(0, now += 100ms, status);
    }
    CHECK(f.s.online(0));
    f.poll(0, now);
    f.run(0, now += 100ms, OutcomeStatus::timeout);
    REQUIRE_FALSE(f.s.online(0));
    // The probe is answered with a misfit: the device is there, back online; the read
    // itself is not retried.
    f.poll(0, now);
    f.run(0, now += 2s, OutcomeStatus::bad_reply);
    CHECK(f.s.online(0));
    CHECK_FALSE(f.s.next(now).has_value());
}

TEST_CASE("offline: other outcomes neither count nor reset") {
    Fixture f;
    TimePoint now = t0;
    f.poll(0, now);
    f.run(0, now += 10ms, OutcomeStatus::timeout);
    f.poll(0, now);
    f.run(0, now += 10ms, OutcomeStatus::timeout);
    f.poll(0, now);
    f.run(0, now += 10ms, OutcomeStatus::expired);  // never reached the device
    CHECK(f.s.online(0));
    f.poll(0, now);
    f.run(0, now += 10ms, OutcomeStatus::timeout);
    CHECK_FALSE(f.s.online(0));
}

TEST_CASE("offline: the queue is trimmed to the one request that goes first; others rejected") {
    Fixture f;
    TimePoint now = t0;
    f.poll(0, now);
    f.run(0, now += 10ms, OutcomeStatus::timeout);
    f.poll(0, now);
    f.run(0, now += 10ms, OutcomeStatus::timeout);
    const auto read = f.poll(0, now, Priority::on_demand);
    const auto p1 = f.poll(0, now);
    const auto p2 = f.poll(0, now);
    const auto p3 = f.poll(0, now);
    // The third timeout: the on-demand read was in flight.
    f.run(0, now += 10ms, OutcomeStatus::timeout);
    CHECK(f.r.status(read) == OutcomeStatus::timeout);
    CHECK_FALSE(f.s.online(0));
    CHECK(f.s.queued(0) == 1);  // the oldest poll is held
    CHECK(f.r.calls(p1) == 0);
    CHECK(f.r.status(p2) == OutcomeStatus::device_offline);
    CHECK(f.r.status(p3) == OutcomeStatus::device_offline);
    // Anything else while it holds one, commands included: device_offline at once.
    const auto more = f.poll(0, now);
    CHECK(f.r.status(more) == OutcomeStatus::device_offline);
    f.s.submit(tagged(write_tx(0, 1, 0x0601, 1), f.r, "cmd"), now);
    CHECK(f.r.status("cmd") == OutcomeStatus::device_offline);
    CHECK(f.s.stats(0)->of(Priority::poll).depth == 1);
    CHECK(f.s.stats(0)->of(Priority::poll).outcome(OutcomeStatus::device_offline) == 3);
    CHECK(f.s.stats(0)->of(Priority::command).outcome(OutcomeStatus::device_offline) == 1);
    // The other device is not affected.
    const auto live = f.poll(1, now);
    f.run(1, now, OutcomeStatus::ok);
    CHECK(f.r.status(live) == OutcomeStatus::ok);
}

TEST_CASE("offline: the held request is the probe; back-off doubles up to the maximum") {
    Fixture f;
    TimePoint now = t0;
    for (int i = 0; i < 3; ++i) {
        f.poll(0, now);
        f.run(0, now += 100ms, OutcomeStatus::timeout);
    }
    REQUIRE_FALSE(f.s.online(0));
    const TimePoint offline_at = now;
    // Expected probe times: +1 s, then each failed probe doubles: 2, 4, 5 (max), 5.
    std::vector<Duration> expected_gaps{1s, 2s, 4s, 5s, 5s};
    TimePoint last = offline_at;
    for (const Duration gap : expected_gaps) {
        f.poll(0, now);  // the agent keeps polling: the first submit is held
        CHECK(f.s.probe_due(0) == last + gap);
        CHECK(f.s.next_wakeup(now) == last + gap);
        CHECK_FALSE(f.s.next(last + gap - 1ms).has_value());  // not before its time
        now = last + gap;
        f.run(0, now, OutcomeStatus::timeout);  // the probe, as soon as due; times out at once here
        last = now;
    }
    CHECK(f.s.stats(0)->went_offline == 1);
    CHECK(f.health.events.size() == 1);
}

TEST_CASE("offline: any valid reply brings it back online at once, back-off reset") {
    Fixture f;
    TimePoint now = t0;
    for (int i = 0; i < 3; ++i) {
        f.poll(0, now);
        f.run(0, now += 100ms, OutcomeStatus::timeout);
    }
    f.poll(0, now);
    now = *f.s.probe_due(0);
    f.run(0, now, OutcomeStatus::timeout);  // back-off now 2 s
    const auto probe = f.poll(0, now);
    now = *f.s.probe_due(0);
    f.run(0, now += 3ms, OutcomeStatus::ok);  // a reply, even an exception reply, is ok
    CHECK(f.r.status(probe) == OutcomeStatus::ok);
    CHECK(f.s.online(0));
    REQUIRE(f.health.events.size() == 2);
    CHECK(f.health.events[1] == std::make_pair(fe::DeviceIndex{0}, true));
    CHECK(f.s.stats(0)->came_online == 1);
    // Online again: queues as usual, and a new failure run starts from 1 s again.
    f.poll(0, now);
    f.poll(0, now);
    CHECK(f.s.queued(0) == 2);
    for (int i = 0; i < 3; ++i) {
        if (f.s.queued(0) == 0) f.poll(0, now);
        f.run(0, now += 100ms, OutcomeStatus::timeout);
    }
    CHECK_FALSE(f.s.online(0));
    CHECK(f.s.probe_due(0) == now + 1s);
}

TEST_CASE("offline: requests to live devices go before a due probe") {
    Fixture f;
    TimePoint now = t0;
    for (int i = 0; i < 3; ++i) {
        f.poll(0, now);
        f.run(0, now += 100ms, OutcomeStatus::timeout);
    }
    auto held = read_tx(0, 1, Priority::poll);
    held.poll_period = 10s;  // no ageing in this test
    f.s.submit(tagged(std::move(held), f.r, "probe"), now);
    now = *f.s.probe_due(0);
    auto live = read_tx(1, 2, Priority::poll);
    live.poll_period = 10s;
    f.s.submit(tagged(std::move(live), f.r, "live"), now);  // newer than the probe, same class
    f.run(1, now, OutcomeStatus::ok);
    CHECK(f.r.status("live") == OutcomeStatus::ok);
    CHECK(f.r.calls("probe") == 0);
    f.run(0, now, OutcomeStatus::timeout);  // the line is free of live work: the probe goes
    CHECK(f.r.status("probe") == OutcomeStatus::timeout);
    // A higher class still goes first: a held on-demand read beats a live poll.
    f.s.submit(tagged(read_tx(0, 1, Priority::on_demand), f.r, "probe-read"), now);
    now = *f.s.probe_due(0);
    auto live2 = read_tx(1, 2, Priority::poll);
    live2.poll_period = 10s;
    f.s.submit(tagged(std::move(live2), f.r, "live2"), now);
    f.run(0, now, OutcomeStatus::ok);
    CHECK(f.r.status("probe-read") == OutcomeStatus::ok);
    CHECK(f.s.online(0));
}

TEST_CASE("offline: a due probe is not starved by a saturated line") {
    fe::DeviceLimits limits = dead_device_limits();
    Fixture f(limits);
    TimePoint now = t0;
    for (int i = 0; i < 3; ++i) {
        f.poll(0, now);
        f.run(0, now += 100ms, OutcomeStatus::timeout);
    }
    auto held = read_tx(0, 1, Priority::poll);
    held.poll_period = 200ms;
    f.s.submit(tagged(std::move(held), f.r, "probe"), now);
    const TimePoint due = *f.s.probe_due(0);  // backoff 1 s
    // Device 1 keeps the line saturated with on-demand reads, 5 ms each.
    std::optional<TimePoint> probed;
    int n = 0;
    while (!probed && now < t0 + 10s) {
        while (f.s.queued(1) < 2) {
            f.s.submit(tagged(read_tx(1, 2, Priority::on_demand), f.r, "r" + std::to_string(n++)), now);
        }
        auto t = f.s.next(now);
        REQUIRE(t.has_value());
        if (t->device == 0) probed = now;
        fe::Outcome ok;
        ok.status = t->device == 0 ? OutcomeStatus::timeout : OutcomeStatus::ok;
        ++t->attempts;
        now += 5ms;
        f.s.finished(std::move(*t), ok, now);
    }
    REQUIRE(probed.has_value());
    // Live reads first while the probe is fresh; it competes as live after one more
    // back-off interval, and goes at the next pick.
    CHECK(*probed >= due + 1s);
    CHECK(*probed <= due + 1s + 5ms);
    CHECK(f.r.status("probe") == OutcomeStatus::timeout);
}

TEST_CASE("offline: a held command still expires at its deadline before the probe") {
    Fixture f;
    TimePoint now = t0;
    for (int i = 0; i < 3; ++i) {
        f.poll(0, now);
        f.run(0, now += 100ms, OutcomeStatus::timeout);
    }
    auto cmd = write_tx(0, 1, 0x0601, 1);
    cmd.deadline = now + 500ms;
    f.s.submit(tagged(std::move(cmd), f.r, "cmd"), now);
    CHECK(f.s.next_wakeup(now) == now + 500ms);  // the deadline comes before the probe
    CHECK_FALSE(f.s.next(now + 500ms).has_value());
    CHECK(f.r.status("cmd") == OutcomeStatus::expired);
    CHECK(f.s.queued(0) == 0);
    // Nothing held: the next submit is held again.
    const auto p = f.poll(0, now + 600ms);
    CHECK(f.r.calls(p) == 0);
}

TEST_CASE("offline: a read's retry is dropped when its device goes offline") {
    fe::DeviceLimits limits = dead_device_limits();
    limits.read_retries = 3;
    limits.offline_after = 2;
    Fixture f(limits);
    const auto tag = f.poll(0, t0);
    f.run(0, t0 + 100ms, OutcomeStatus::timeout);  // 1st timeout: retried
    CHECK(f.r.calls(tag) == 0);
    f.run(0, t0 + 200ms, OutcomeStatus::timeout);  // 2nd: offline, no more retries
    CHECK(f.r.status(tag) == OutcomeStatus::timeout);
    CHECK(f.r.outcome(tag).attempts == 2);
    CHECK_FALSE(f.s.online(0));
    CHECK(f.s.queued(0) == 0);
}

}  // namespace
