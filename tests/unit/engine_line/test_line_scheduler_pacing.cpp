// LineScheduler: per-device pacing (issue 27): request_gap between the end of a
// device's transaction and its next request, first_request_delay after the line
// opens; other devices take the line meanwhile.
#include <doctest/doctest.h>

#include "line_test_support.hpp"

namespace {

using namespace line_test;
using fe::OutcomeStatus;

void finish_ok(Scheduler& s, Transaction t, TimePoint now) {
    t.attempts = 1;
    fe::Outcome outcome;
    outcome.status = OutcomeStatus::ok;
    outcome.finished = now;
    outcome.attempts = 1;
    s.finished(std::move(t), outcome, now);
}

TEST_CASE("pacing: a device's request_gap holds its next request; another device goes meanwhile") {
    Scheduler s;
    fe::DeviceLimits slow;
    slow.request_gap = 50ms;
    s.add_device(0, slow);
    s.add_device(1, fe::DeviceLimits{});
    s.submit(read_tx(0, 1, Priority::poll), t0);
    auto first = s.next(t0);
    REQUIRE(first);
    finish_ok(s, std::move(*first), t0 + 2ms);

    s.submit(read_tx(0, 1, Priority::command), t0 + 3ms);
    s.submit(read_tx(1, 2, Priority::poll), t0 + 3ms);
    auto other = s.next(t0 + 3ms);
    REQUIRE(other);
    CHECK(other->device == 1);  // the command to the paced device waits, the line does not
    finish_ok(s, std::move(*other), t0 + 5ms);
    CHECK_FALSE(s.next(t0 + 20ms).has_value());
    CHECK(s.next_wakeup(t0 + 20ms) == t0 + 52ms);
    auto paced = s.next(t0 + 52ms);
    REQUIRE(paced);
    CHECK(paced->device == 0);
}

TEST_CASE("pacing: first_request_delay counts from each open of the line") {
    Scheduler s;
    fe::DeviceLimits meter;
    meter.first_request_delay = 200ms;
    s.add_device(0, meter);
    s.line_opened(t0);
    s.submit(read_tx(0, 1, Priority::poll), t0);
    CHECK_FALSE(s.next(t0 + 199ms).has_value());
    CHECK(s.next_wakeup(t0) == t0 + 200ms);
    auto first = s.next(t0 + 200ms);
    REQUIRE(first);
    finish_ok(s, std::move(*first), t0 + 202ms);
    // A reconnect later: the delay again.
    s.line_opened(t0 + 1s);
    s.submit(read_tx(0, 1, Priority::poll), t0 + 1s);
    CHECK_FALSE(s.next(t0 + 1s + 100ms).has_value());
    CHECK(s.next(t0 + 1s + 200ms).has_value());
}

TEST_CASE("pacing: without it a device goes back to back (no change for other lines)") {
    Scheduler s;
    s.add_device(0, fe::DeviceLimits{});
    s.line_opened(t0);
    s.submit(read_tx(0, 1, Priority::poll), t0);
    auto first = s.next(t0);
    REQUIRE(first);
    finish_ok(s, std::move(*first), t0 + 1ms);
    s.submit(read_tx(0, 1, Priority::poll), t0 + 1ms);
    CHECK(s.next(t0 + 1ms).has_value());
}

}  // namespace
