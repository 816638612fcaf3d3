// LineScheduler: priority classes, urgent commands, deadlines, queue limits, retries,
// poll ageing and the fairness bound (product spec section 3, rules 1-4, 6, 9).
#include <doctest/doctest.h>

#include <string>

#include "core/error.hpp"
#include "line_test_support.hpp"

namespace {

using namespace line_test;
using fe::OutcomeStatus;

Scheduler make_scheduler(std::size_t devices = 3, fe::DeviceLimits limits = {},
                         fe::SchedulerConfig config = {"A"}) {
    Scheduler scheduler(std::move(config));
    for (std::size_t i = 0; i < devices; ++i) scheduler.add_device(static_cast<fe::DeviceIndex>(i), limits);
    return scheduler;
}

/// Picks the next transaction and completes it as @p status (ok by default).
std::uint64_t run_next(Scheduler& s, TimePoint now, OutcomeStatus status = OutcomeStatus::ok,
                       unsigned attempts = 1) {
    auto t = s.next(now);
    REQUIRE(t.has_value());
    const auto id = t->id;
    t->attempts += attempts;
    fe::Outcome outcome;
    outcome.status = status;
    outcome.finished = now;
    outcome.attempts = t->attempts;
    s.finished(std::move(*t), outcome, now);
    return id;
}

std::string next_tag(Scheduler& s, Recorder& r, TimePoint now) {
    const auto before = r.total();
    run_next(s, now);
    REQUIRE(r.total() == before + 1);
    return r.order().back();
}

TEST_CASE("scheduler: a command overtakes queued polls and on-demand reads") {
    auto s = make_scheduler();
    Recorder r;
    s.submit(tagged(read_tx(0, 1, Priority::poll), r, "poll0"), t0);
    s.submit(tagged(read_tx(1, 2, Priority::poll), r, "poll1"), t0 + 1ms);
    s.submit(tagged(read_tx(2, 3, Priority::on_demand), r, "read2"), t0 + 2ms);
    s.submit(tagged(write_tx(1, 2, 0x0620, 1), r, "stop"), t0 + 3ms);
    CHECK(s.queued() == 4);
    CHECK(next_tag(s, r, t0 + 4ms) == "stop");
    CHECK(next_tag(s, r, t0 + 5ms) == "read2");
    CHECK(next_tag(s, r, t0 + 6ms) == "poll0");
    CHECK(next_tag(s, r, t0 + 7ms) == "poll1");
    CHECK_FALSE(s.next(t0 + 8ms).has_value());
    for (const auto* tag : {"poll0", "poll1", "read2", "stop"}) CHECK(r.status(tag) == OutcomeStatus::ok);
}

TEST_CASE("scheduler: a command waits only for the transaction in flight") {
    auto s = make_scheduler();
    Recorder r;
    for (int i = 0; i < 5; ++i) {
        s.submit(tagged(read_tx(0, 1, Priority::poll), r, "poll" + std::to_string(i)), t0);
    }
    auto in_flight = s.next(t0);  // the line is busy with poll0
    REQUIRE(in_flight.has_value());
    s.submit(tagged(write_tx(0, 1, 0x0601, 1), r, "trigger"), t0 + 1ms);
    CHECK(r.total() == 0);
    fe::Outcome ok;
    ok.status = OutcomeStatus::ok;
    s.finished(std::move(*in_flight), ok, t0 + 3ms);
    CHECK(r.order().back() == "poll0");
    CHECK(next_tag(s, r, t0 + 3ms) == "trigger");
    // Its wait (submit -> start) was the rest of the one in flight.
    const auto& command_stats = s.stats(0)->of(Priority::command);
    CHECK(command_stats.wait.count() == 1);
    CHECK(command_stats.wait.max() == 2ms);
    CHECK(s.stats(0)->device_exceptions == 0);
}

TEST_CASE("scheduler: a device's exception replies are counted, and keep it online") {
    auto s = make_scheduler();
    Recorder r;
    s.submit(tagged(write_tx(0, 1, 0x0601, 1), r, "refused"), t0);
    auto t = s.next(t0);
    REQUIRE(t.has_value());
    fe::Outcome refused;
    refused.status = OutcomeStatus::ok;
    refused.reply = fp::Response{fp::ExceptionResponse{0x10, fp::ExceptionCode::server_device_failure}};
    s.finished(std::move(*t), refused, t0 + 1ms);
    CHECK(r.status("refused") == OutcomeStatus::ok);
    CHECK(s.stats(0)->device_exceptions == 1);
    CHECK(s.online(0));
}

TEST_CASE("scheduler: urgent commands jump every other queued command, first come first served") {
    auto s = make_scheduler();
    Recorder r;
    s.submit(tagged(write_tx(0, 1, 0x0630, 100), r, "move0"), t0);
    s.submit(tagged(write_tx(1, 2, 0x0630, 200), r, "move1"), t0 + 1ms);
    auto stop1 = write_tx(1, 2, 0x0620, 1);
    stop1.urgent = true;
    s.submit(tagged(std::move(stop1), r, "stop1"), t0 + 2ms);
    auto stop0 = write_tx(0, 1, 0x0620, 1);
    stop0.urgent = true;
    s.submit(tagged(std::move(stop0), r, "stop0"), t0 + 3ms);
    CHECK(next_tag(s, r, t0 + 4ms) == "stop1");
    CHECK(next_tag(s, r, t0 + 5ms) == "stop0");
    CHECK(next_tag(s, r, t0 + 6ms) == "move0");
    CHECK(next_tag(s, r, t0 + 7ms) == "move1");
}

TEST_CASE("scheduler: same class across devices goes oldest first") {
    auto s = make_scheduler();
    Recorder r;
    s.submit(tagged(read_tx(2, 3, Priority::on_demand), r, "a"), t0);
    s.submit(tagged(read_tx(0, 1, Priority::on_demand), r, "b"), t0 + 1ms);
    s.submit(tagged(read_tx(2, 3, Priority::on_demand), r, "c"), t0 + 2ms);
    CHECK(next_tag(s, r, t0 + 3ms) == "a");
    CHECK(next_tag(s, r, t0 + 3ms) == "b");
    CHECK(next_tag(s, r, t0 + 3ms) == "c");
}

TEST_CASE("scheduler: an expired command never reaches next()") {
    auto s = make_scheduler();
    Recorder r;
    auto grip = write_tx(0, 1, 0x0601, 1);
    grip.deadline = t0 + 500ms;
    s.submit(tagged(std::move(grip), r, "grip"), t0);
    s.submit(tagged(read_tx(1, 2, Priority::poll), r, "poll"), t0);
    // The line was busy until after the deadline: the command is completed, the poll goes.
    auto picked = s.next(t0 + 500ms);
    REQUIRE(picked.has_value());
    CHECK(picked->device == 1);
    CHECK(r.status("grip") == OutcomeStatus::expired);
    CHECK(r.outcome("grip").attempts == 0);
    CHECK(r.outcome("grip").finished == t0 + 500ms);
    CHECK(s.stats(0)->of(Priority::command).outcome(OutcomeStatus::expired) == 1);
    CHECK(s.stats(0)->of(Priority::command).started == 0);
    CHECK(s.stats(0)->of(Priority::command).depth == 0);
}

TEST_CASE("scheduler: one nanosecond before its deadline a command still goes") {
    auto s = make_scheduler();
    Recorder r;
    auto grip = write_tx(0, 1, 0x0601, 1);
    grip.deadline = t0 + 500ms;
    s.submit(tagged(std::move(grip), r, "grip"), t0);
    auto picked = s.next(t0 + 500ms - 1ns);
    REQUIRE(picked.has_value());
    CHECK(r.total() == 0);
}

TEST_CASE("scheduler: submitting an already expired transaction completes it at once") {
    auto s = make_scheduler();
    Recorder r;
    auto late = write_tx(0, 1, 0x0601, 1);
    late.deadline = t0;
    s.submit(tagged(std::move(late), r, "late"), t0);
    CHECK(r.status("late") == OutcomeStatus::expired);
    CHECK(s.queued() == 0);
    CHECK_FALSE(s.next(t0).has_value());
}

TEST_CASE("scheduler: expire() and next_wakeup() complete a deadline while the line is busy") {
    auto s = make_scheduler();
    Recorder r;
    auto grip = write_tx(0, 1, 0x0601, 1);
    grip.deadline = t0 + 20ms;
    s.submit(tagged(read_tx(1, 2, Priority::poll), r, "poll"), t0);
    auto in_flight = s.next(t0);
    REQUIRE(in_flight.has_value());
    s.submit(tagged(std::move(grip), r, "grip"), t0 + 1ms);
    CHECK(s.next_wakeup(t0 + 1ms) == t0 + 1ms);  // eligible now
    s.expire(t0 + 19ms);
    CHECK(r.calls("grip") == 0);
    s.expire(t0 + 20ms);
    CHECK(r.status("grip") == OutcomeStatus::expired);
    CHECK_FALSE(s.next_wakeup(t0 + 20ms).has_value());
}

TEST_CASE("scheduler: the per-device queue limit rejects with queue_full at once") {
    fe::DeviceLimits limits;
    limits.queue_limit = 2;
    auto s = make_scheduler(2, limits);
    Recorder r;
    s.submit(tagged(read_tx(0, 1, Priority::poll), r, "a"), t0);
    s.submit(tagged(write_tx(0, 1, 0x0601, 1), r, "b"), t0);
    s.submit(tagged(write_tx(0, 1, 0x0601, 1), r, "c"), t0);
    CHECK(r.status("c") == OutcomeStatus::queue_full);
    CHECK(r.calls("a") == 0);
    CHECK(r.calls("b") == 0);
    s.submit(tagged(read_tx(1, 2, Priority::poll), r, "other"), t0);  // another device is not affected
    CHECK(r.calls("other") == 0);
    CHECK(s.queued(0) == 2);
    CHECK(s.stats(0)->of(Priority::command).outcome(OutcomeStatus::queue_full) == 1);
    CHECK(s.stats(0)->of(Priority::command).depth == 1);
    CHECK(s.stats(0)->of(Priority::poll).depth == 1);
    run_next(s, t0);  // b leaves the queue: room again
    s.submit(tagged(write_tx(0, 1, 0x0601, 1), r, "d"), t0);
    CHECK(r.calls("d") == 0);
}

TEST_CASE("scheduler: a read that timed out is retried once at the front, then fails") {
    fe::DeviceLimits limits;
    limits.read_retries = 1;
    limits.offline_after = 10;
    auto s = make_scheduler(1, limits);
    Recorder r;
    s.submit(tagged(read_tx(0, 1, Priority::poll), r, "status"), t0);
    s.submit(tagged(read_tx(0, 1, Priority::poll), r, "inputs"), t0);
    auto first = s.next(t0);
    REQUIRE(first.has_value());
    const auto id = first->id;
    first->attempts = 1;
    fe::Outcome timeout;
    timeout.status = OutcomeStatus::timeout;
    timeout.attempts = 1;
    s.finished(std::move(*first), timeout, t0 + 100ms);
    CHECK(r.total() == 0);  // not completed: re-queued
    auto again = s.next(t0 + 100ms);
    REQUIRE(again.has_value());
    CHECK(again->id == id);  // at the front, ahead of the older "inputs"
    CHECK(again->attempts == 1);
    again->attempts = 2;
    timeout.attempts = 2;
    s.finished(std::move(*again), timeout, t0 + 200ms);
    CHECK(r.status("status") == OutcomeStatus::timeout);
    CHECK(r.outcome("status").attempts == 2);
    CHECK(s.stats(0)->of(Priority::poll).retries == 1);
    CHECK(s.stats(0)->of(Priority::poll).started == 2);
}

TEST_CASE("scheduler: with read_retries 0 a read is not retried") {
    fe::DeviceLimits limits;
    limits.read_retries = 0;
    auto s = make_scheduler(1, limits);
    Recorder r;
    s.submit(tagged(read_tx(0, 1, Priority::on_demand), r, "read"), t0);
    run_next(s, t0, OutcomeStatus::timeout);
    CHECK(r.status("read") == OutcomeStatus::timeout);
}

TEST_CASE("scheduler: a write that timed out is never retried, even if flagged retryable") {
    std::vector<std::string> logs;
    Recorder r;
    Scheduler logged({"A"}, fe::LogSink{[&](fe::LogLevel level, std::string_view m) {
                                                    if (level == fe::LogLevel::warning) logs.emplace_back(m);
                                                },
                                                fe::LogLevel::info});
    logged.add_device(0, {});
    logged.submit(tagged(write_tx(0, 1, 0x0630, 500), r, "move"), t0);
    auto wrongly_flagged = write_tx(0, 1, 0x0630, 600);
    wrongly_flagged.retry_allowed = true;  // a profile bug must not cause a double move
    logged.submit(tagged(std::move(wrongly_flagged), r, "move2"), t0);
    run_next(logged, t0, OutcomeStatus::timeout);
    run_next(logged, t0, OutcomeStatus::timeout);
    CHECK(r.status("move") == OutcomeStatus::timeout);
    CHECK(r.outcome("move").attempts == 1);
    CHECK(r.status("move2") == OutcomeStatus::timeout);
    CHECK(logged.queued() == 0);
    REQUIRE(logs.size() == 2);
    CHECK(logs[0].find("write timed out, not retried") != std::string::npos);
    CHECK(logs[0].find("line A device 0") != std::string::npos);
}

TEST_CASE("scheduler: log messages name a device by its config name when it has one") {
    std::vector<std::string> logs;
    Recorder r;
    Scheduler logged({"A"}, fe::LogSink{[&](fe::LogLevel level, std::string_view m) {
                                                    if (level == fe::LogLevel::warning) logs.emplace_back(m);
                                                },
                                                fe::LogLevel::info});
    fe::DeviceLimits limits;
    limits.offline_after = 1;
    logged.add_device(0, limits, "gripper-left");
    logged.submit(tagged(read_tx(0, 1, Priority::poll), r, "poll"), t0);
    run_next(logged, t0, OutcomeStatus::timeout);
    REQUIRE_FALSE(logs.empty());
    CHECK(logs.back().find("line A device 'gripper-left': offline after 1 consecutive timeouts") == 0);
}

TEST_CASE("scheduler: polls age into the on-demand class and are not starved by reads") {
    auto s = make_scheduler(2);
    Recorder r;
    auto poll = read_tx(0, 1, Priority::poll);
    poll.poll_period = 50ms;
    s.submit(tagged(std::move(poll), r, "poll"), t0);
    // Device 1 keeps two on-demand reads queued; each transaction takes 5 ms.
    int reads = 0;
    const auto top_up = [&](TimePoint now) {
        while (s.queued(1) < 2) {
            s.submit(tagged(read_tx(1, 2, Priority::on_demand), r, "read" + std::to_string(reads++)), now);
        }
    };
    TimePoint now = t0;
    std::optional<TimePoint> poll_started;
    while (!poll_started && now < t0 + 1s) {
        top_up(now);
        auto t = s.next(now);
        REQUIRE(t.has_value());
        if (t->device == 0) poll_started = now;
        fe::Outcome ok;
        ok.status = OutcomeStatus::ok;
        now += 5ms;
        s.finished(std::move(*t), ok, now);
    }
    REQUIRE(poll_started.has_value());
    // Not before it aged (waited more than 50 ms), and then at the first pick after the
    // reads that were queued before it aged.
    CHECK(*poll_started > t0 + 50ms);
    CHECK(*poll_started <= t0 + 50ms + 2 * 5ms);
    CHECK(r.status("poll") == OutcomeStatus::ok);
}

TEST_CASE("scheduler: a poll without a period ages after the configured default") {
    fe::SchedulerConfig config{"A"};
    config.default_poll_age = 20ms;
    auto s = make_scheduler(2, {}, config);
    Recorder r;
    s.submit(tagged(read_tx(0, 1, Priority::poll), r, "poll"), t0);
    s.submit(tagged(read_tx(1, 2, Priority::on_demand), r, "read"), t0 + 20ms);
    // At 20 ms exactly the poll has not waited LONGER than its age: the read goes.
    CHECK(next_tag(s, r, t0 + 20ms) == "read");
    s.submit(tagged(read_tx(1, 2, Priority::on_demand), r, "read2"), t0 + 20ms);
    // Past it, the poll joined the on-demand class at t0 + 20 ms, the moment read2 was
    // submitted: equal times, and the poll was queued first.
    CHECK(next_tag(s, r, t0 + 21ms) == "poll");
}

TEST_CASE("scheduler: commands outrank aged polls, within the command_burst bound") {
    fe::SchedulerConfig config{"A"};
    config.command_burst = 4;
    auto s = make_scheduler(2, {}, config);
    Recorder r;
    auto poll = read_tx(0, 1, Priority::poll);
    poll.poll_period = 10ms;
    s.submit(tagged(std::move(poll), r, "poll"), t0);
    int commands = 0;
    const auto top_up = [&](TimePoint now) {
        while (s.queued(1) < 2) {
            s.submit(tagged(write_tx(1, 2, 0x0630, 1), r, "cmd" + std::to_string(commands++)), now);
        }
    };
    // Before the poll aged, commands go however many there are (it is not counted).
    TimePoint now = t0;
    for (int i = 0; i < 8; ++i, now += 1ms) {
        top_up(now);
        CHECK(next_tag(s, r, now).rfind("cmd", 0) == 0);
    }
    CHECK(r.calls("poll") == 0);
    // Aged (waited > 10 ms): exactly command_burst more commands, then the poll, once.
    now = t0 + 11ms;
    for (int i = 0; i < 4; ++i, now += 1ms) {
        top_up(now);
        CHECK(next_tag(s, r, now).rfind("cmd", 0) == 0);
    }
    top_up(now);
    CHECK(next_tag(s, r, now) == "poll");
    top_up(now);
    CHECK(next_tag(s, r, now).rfind("cmd", 0) == 0);
}

TEST_CASE("scheduler: urgent commands are never held back by the fairness bound") {
    fe::SchedulerConfig config{"A"};
    config.command_burst = 2;
    auto s = make_scheduler(2, {}, config);
    Recorder r;
    s.submit(tagged(read_tx(0, 1, Priority::on_demand), r, "read"), t0);
    s.submit(tagged(write_tx(1, 2, 0x0630, 1), r, "c1"), t0);
    s.submit(tagged(write_tx(1, 2, 0x0630, 1), r, "c2"), t0);
    CHECK(next_tag(s, r, t0) == "c1");
    CHECK(next_tag(s, r, t0) == "c2");
    auto stop = write_tx(1, 2, 0x0620, 1);
    stop.urgent = true;
    s.submit(tagged(std::move(stop), r, "stop"), t0);
    s.submit(tagged(write_tx(1, 2, 0x0630, 1), r, "c3"), t0);
    CHECK(next_tag(s, r, t0) == "stop");  // the burst is used up, but stop is urgent
    CHECK(next_tag(s, r, t0) == "read");  // the bound: the read goes before c3
    CHECK(next_tag(s, r, t0) == "c3");
}

TEST_CASE("scheduler: command_burst 0 means commands always go first") {
    fe::SchedulerConfig config{"A"};
    config.command_burst = 0;
    auto s = make_scheduler(2, {}, config);
    Recorder r;
    s.submit(tagged(read_tx(0, 1, Priority::on_demand), r, "read"), t0);
    for (int i = 0; i < 20; ++i) {
        s.submit(tagged(write_tx(1, 2, 0x0630, 1), r, "c" + std::to_string(i)), t0);
        CHECK(next_tag(s, r, t0) == "c" + std::to_string(i));
    }
    CHECK(next_tag(s, r, t0) == "read");
}

TEST_CASE("scheduler: cancel_all completes everything; a turned-away submission completes at once, counted") {
    auto s = make_scheduler(2);
    Recorder r;
    s.turn_away(tagged(read_tx(0, 1, Priority::poll), r, "c"), OutcomeStatus::line_down, t0 + 2ms);
    CHECK(r.status("c") == OutcomeStatus::line_down);
    CHECK(s.stats(0)->of(Priority::poll).outcome(OutcomeStatus::line_down) == 1);
    CHECK(s.queued() == 0);
    s.submit(tagged(read_tx(0, 1, Priority::poll), r, "d"), t0 + 4ms);
    s.submit(tagged(read_tx(1, 2, Priority::on_demand), r, "e"), t0 + 4ms);
    CHECK(r.calls("d") == 0);
    s.cancel_all(OutcomeStatus::cancelled, t0 + 5ms);
    CHECK(r.status("d") == OutcomeStatus::cancelled);
    CHECK(r.status("e") == OutcomeStatus::cancelled);
    CHECK(s.queued() == 0);
    CHECK(s.stats(0)->of(Priority::poll).depth == 0);
}

TEST_CASE("scheduler: an unknown device is refused, device setup is checked") {
    auto s = make_scheduler(1);
    Recorder r;
    s.submit(tagged(read_tx(7, 1, Priority::poll), r, "ghost"), t0);
    CHECK(r.status("ghost") == OutcomeStatus::invalid_request);
    CHECK_THROWS_AS(s.add_device(0, {}), fieldbridge::core::InvalidArgument);
    CHECK_THROWS_AS(s.add_device(fe::broadcast_device, {}), fieldbridge::core::InvalidArgument);
    fe::DeviceLimits bad;
    bad.queue_limit = 0;
    CHECK_THROWS_AS(s.add_device(1, bad), fieldbridge::core::InvalidArgument);
    bad = {};
    bad.offline_after = 0;
    CHECK_THROWS_AS(s.add_device(1, bad), fieldbridge::core::InvalidArgument);
    bad = {};
    bad.backoff_max = bad.backoff_initial / 2;
    CHECK_THROWS_WITH_AS(s.add_device(1, bad), doctest::Contains("line A device 1"),
                         fieldbridge::core::InvalidArgument);
    CHECK_FALSE(s.has_device(1));
}

TEST_CASE("scheduler: broadcasts queue on the broadcast pseudo-device and never touch health") {
    auto s = make_scheduler(1);
    Recorder r;
    auto broadcast = write_tx(fe::broadcast_device, 0, 0x0620, 1);
    s.submit(tagged(std::move(broadcast), r, "all-stop"), t0);
    CHECK(s.queued(fe::broadcast_device) == 1);
    run_next(s, t0, OutcomeStatus::broadcast_sent);
    CHECK(r.status("all-stop") == OutcomeStatus::broadcast_sent);
    CHECK(s.online(fe::broadcast_device));
}

TEST_CASE("scheduler: ids are unique and enqueued is set; on_done may submit again") {
    auto s = make_scheduler(1);
    int follow_ups = 0;
    Transaction first = read_tx(0, 1, Priority::poll);
    first.on_done = [&](const fe::Outcome& outcome) {
        CHECK(outcome.status == OutcomeStatus::ok);
        auto next = read_tx(0, 1, Priority::poll);
        next.on_done = [&](const fe::Outcome&) { ++follow_ups; };
        s.submit(std::move(next), t0 + 5ms);  // a submit from a completion
    };
    s.submit(std::move(first), t0);
    auto picked = s.next(t0 + 1ms);
    REQUIRE(picked.has_value());
    CHECK(picked->id == 1);
    CHECK(picked->enqueued == t0);
    fe::Outcome ok;
    ok.status = OutcomeStatus::ok;
    s.finished(std::move(*picked), ok, t0 + 4ms);
    auto second = s.next(t0 + 5ms);
    REQUIRE(second.has_value());
    CHECK(second->id == 2);
    CHECK(second->enqueued == t0 + 5ms);
    s.finished(std::move(*second), ok, t0 + 8ms);
    CHECK(follow_ups == 1);
}

TEST_CASE("scheduler: a throwing on_done is logged and the other completions still run") {
    std::vector<std::string> errors;
    Scheduler s({"A"}, fe::LogSink{[&](fe::LogLevel level, std::string_view m) {
                                              if (level == fe::LogLevel::error) errors.emplace_back(m);
                                          },
                                          fe::LogLevel::debug});
    s.add_device(0, {});
    Recorder r;
    auto bad = read_tx(0, 1, Priority::poll);
    bad.on_done = [](const fe::Outcome&) { throw std::runtime_error("agent bug"); };
    s.submit(std::move(bad), t0);
    s.submit(tagged(read_tx(0, 1, Priority::poll), r, "good"), t0);
    s.cancel_all(OutcomeStatus::cancelled, t0);
    CHECK(r.status("good") == OutcomeStatus::cancelled);
    REQUIRE(errors.size() == 1);
    CHECK(errors[0].find("agent bug") != std::string::npos);
}

}  // namespace
