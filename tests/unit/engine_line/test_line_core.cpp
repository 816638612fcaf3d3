// LineCore with a fake clock and a scripted port: the worker's behaviours that need
// no I/O (reopen back-off, line down and up, stop, completions exactly once and a
// submit from one, expiry, blocked writes, reading before a decision, the two wake
// timers). The shell (line_core_fake.hpp) answers the core's questions the way the line
// worker does; precise silence timing is in test_line_core_precise.cpp.
#include <doctest/doctest.h>

#include <stdexcept>
#include <utility>

#include "line_core_fake.hpp"

namespace {

using namespace line_core_test;

TEST_CASE("line core: a read goes out after the silence and completes with the reply") {
    FakeLine line;
    line.start();
    REQUIRE(line.core.line_up());
    CHECK(line.states == std::vector<bool>{true});
    CHECK(line.logged(fe::LogLevel::info, "line L: /dev/ttyFAKE open, low latency: test"));

    line.submit(read_tx(0, 1, Priority::poll), "poll");
    CHECK(line.drive_posted);  // never decided inside the submission
    line.advance(0ms);
    CHECK(line.written.empty());  // the silence after the open is not over
    line.advance(1ms);
    CHECK(line.take_written() == read_request);
    line.advance(1ms);
    line.arrive(reply_1());
    CHECK(line.recorder.status("poll") == OutcomeStatus::ok);
    CHECK(line.recorder.outcome("poll").attempts == 1);
    CHECK_FALSE(line.core.master().busy());
}

TEST_CASE("line core: a port missing at start is retried with back-off doubling to the maximum") {
    FakeLine line;
    line.open_failure = "serial port /dev/ttyFAKE: no such file";
    line.start();
    CHECK_FALSE(line.core.line_up());
    CHECK(line.states == std::vector<bool>{false});
    CHECK(line.logged(fe::LogLevel::error, "line L: cannot open /dev/ttyFAKE: serial port /dev/ttyFAKE: no such "
                                           "file; check the adapter and its cable; retrying in 100 ms"));
    REQUIRE(line.reopen_at == t0 + 100ms);

    // A submission while down completes line_down, from the drive, not the submit.
    line.submit(read_tx(0, 1, Priority::poll), "while-down");
    CHECK(line.recorder.calls("while-down") == 0);
    line.advance(0ms);
    CHECK(line.recorder.status("while-down") == OutcomeStatus::line_down);

    line.advance_to(t0 + 100ms);
    CHECK(line.logged(fe::LogLevel::warning, "reopening /dev/ttyFAKE failed (attempt 2): serial port "
                                             "/dev/ttyFAKE: no such file; retrying in 200 ms"));
    REQUIRE(line.reopen_at == t0 + 300ms);
    line.advance_to(t0 + 300ms);
    CHECK(line.logged(fe::LogLevel::warning, "retrying in 350 ms"));  // capped
    REQUIRE(line.reopen_at == t0 + 650ms);

    line.open_failure.reset();
    line.advance_to(t0 + 650ms);
    CHECK(line.core.line_up());
    CHECK(line.core.reopens() == 1);
    CHECK(line.states == std::vector<bool>{false, true});
    CHECK(line.logged(fe::LogLevel::info, "line L: /dev/ttyFAKE reopened after 4 attempts, low latency: test"));
    line.submit(read_tx(0, 1, Priority::poll), "after");
    line.advance(1ms);
    CHECK(line.take_written() == read_request);
}

TEST_CASE("line core: the port fails with work in flight; it all completes line_down once, then the reopen serves") {
    FakeLine line;
    line.start();
    line.submit(read_tx(0, 1, Priority::poll), "in-flight");
    line.submit(read_tx(1, 2, Priority::poll), "queued");
    line.advance(1ms);
    REQUIRE(line.take_written() == read_request);

    line.read_failure = "serial port /dev/ttyFAKE: input/output error (EIO)";
    line.feed(ev::Readable{});
    CHECK(line.closes == 1);
    CHECK_FALSE(line.core.line_up());
    CHECK(line.states == std::vector<bool>{true, false});
    // Aborted after it went out (timeout), re-queued for its retry, then the queue
    // went down with the line.
    CHECK(line.recorder.status("in-flight") == OutcomeStatus::line_down);
    CHECK(line.recorder.status("queued") == OutcomeStatus::line_down);
    CHECK(line.logged(fe::LogLevel::error, "line L: read on the port failed: serial port /dev/ttyFAKE: "
                                           "input/output error (EIO); check the adapter and its cable; "
                                           "retrying in 100 ms"));
    REQUIRE(line.reopen_at == line.now + 100ms);

    // The core's port state alone decides: while it is down a submission completes
    // line_down (from the drive) and is counted as the device's outcome.
    line.submit(read_tx(1, 2, Priority::poll), "while-down");
    line.advance(0ms);
    CHECK(line.recorder.status("while-down") == OutcomeStatus::line_down);
    CHECK(line.core.scheduler().stats(1)->of(Priority::poll).outcome(OutcomeStatus::line_down) == 2);

    line.read_failure.reset();
    line.advance(100ms);
    CHECK(line.core.line_up());
    CHECK(line.core.reopens() == 1);
    CHECK(line.states == std::vector<bool>{true, false, true});
    line.submit(read_tx(0, 1, Priority::poll), "after");
    line.advance(1ms);
    CHECK(line.take_written() == read_request);
    line.arrive(reply_1());
    CHECK(line.recorder.status("after") == OutcomeStatus::ok);
    CHECK(line.recorder.total() == 4);
}

TEST_CASE("line core: stop completes everything cancelled exactly once; later submissions too") {
    FakeLine line;
    line.start();
    send_read(line, "in-flight", Priority::poll, false);
    line.submit(read_tx(1, 2, Priority::poll), "queued");
    line.advance(0ms);
    // Waiting for the reply: taken by the scheduler at once, no drive.
    line.submit(write_tx(1, 2, 0x0601, 1), "queued-write");

    line.feed(ev::Stop{});
    CHECK(line.core.stopped());
    CHECK(line.closes == 1);
    CHECK_FALSE(line.exact_at);
    CHECK_FALSE(line.lazy_at);
    CHECK(line.recorder.status("in-flight") == OutcomeStatus::timeout);  // it went out
    CHECK(line.recorder.status("queued") == OutcomeStatus::cancelled);
    CHECK(line.recorder.status("queued-write") == OutcomeStatus::cancelled);
    CHECK(line.states == std::vector<bool>{true, false});
    CHECK(line.logged(fe::LogLevel::info, "line L: stopped, port /dev/ttyFAKE closed"));

    line.feed(ev::Stop{});  // idempotent
    line.submit(read_tx(0, 1, Priority::poll), "after-stop");
    CHECK(line.recorder.status("after-stop") == OutcomeStatus::cancelled);
    line.advance(1s);
    CHECK(line.written.empty());
    CHECK(line.recorder.total() == 4);
    CHECK(line.states == std::vector<bool>{true, false});
    CHECK_THROWS_AS(line.feed(ev::Start{}), std::logic_error);
}

TEST_CASE("line core: a completion's submission competes for the line before the next pick") {
    FakeLine line;
    line.start();
    line.submit(read_tx(1, 2, Priority::poll), "poll");
    Transaction first = read_tx(0, 1, Priority::on_demand);
    bool follow_up_submitted = false;
    first.on_done = [&](const fe::Outcome& outcome) {
        CHECK(outcome.status == OutcomeStatus::ok);
        // The usual "poll again", here a command: it must go before the queued poll.
        line.feed(ev::Submit{tagged(write_tx(0, 1, 0x0601, 1), line.recorder, "follow-up")});
        follow_up_submitted = true;
    };
    line.feed(ev::Submit{std::move(first)});
    line.advance(1ms);
    REQUIRE(line.take_written().front() == 1);  // the on-demand read
    line.arrive(reply_1());
    REQUIRE(follow_up_submitted);
    line.advance(1ms);
    const Bytes next = line.take_written();
    REQUIRE(next.size() > 2);
    CHECK(next[1] == fp::fc::write_single_register);
    CHECK(line.recorder.calls("poll") == 0);
}

TEST_CASE("line core: a completion may stop the line") {
    FakeLine line;
    line.start();
    line.submit(read_tx(1, 2, Priority::poll), "second");
    Transaction first = read_tx(0, 1, Priority::command);
    first.on_done = [&](const fe::Outcome&) {
        // Submitted during the deliveries: still in the inbox when the line stops.
        line.feed(ev::Submit{tagged(read_tx(0, 1, Priority::poll), line.recorder, "inbox")});
        line.feed(ev::Stop{});
    };
    line.feed(ev::Submit{std::move(first)});
    line.advance(1ms);
    line.take_written();
    line.arrive(reply_1());
    CHECK(line.core.stopped());
    CHECK(line.recorder.status("second") == OutcomeStatus::cancelled);
    CHECK(line.recorder.status("inbox") == OutcomeStatus::cancelled);
    line.advance(1s);
    CHECK(line.written.empty());
}

TEST_CASE("line core: a command whose deadline passes behind the one in flight never reaches the wire") {
    FakeLine line;
    line.start();
    send_read(line, "slow");
    Transaction command = write_tx(1, 2, 0x0601, 1);
    command.deadline = line.now + 10ms;
    line.submit(std::move(command), "command");
    line.advance(20ms);  // the reply comes after the command's deadline
    line.arrive(reply_1());
    CHECK(line.recorder.status("slow") == OutcomeStatus::ok);
    CHECK(line.recorder.status("command") == OutcomeStatus::expired);
    CHECK(line.recorder.outcome("command").attempts == 0);
    line.advance(10ms);
    CHECK(line.written.empty());
}

TEST_CASE("line core: a request the driver takes in pieces resumes on writability, and only then") {
    FakeLine line;
    line.start();
    line.write_capacity = 3;
    line.submit(read_tx(0, 1, Priority::poll), "poll");
    line.advance(1ms);
    CHECK(line.written.size() == 3);
    CHECK(line.watching_writable);
    CHECK(line.core.master().state() == fe::MasterState::sending);
    // A timer or a readiness report meanwhile does not write around the block.
    line.feed(ev::TimerFired{fe::WakeTimer::exact});
    CHECK(line.written.size() == 3);

    line.write_capacity = 100;
    line.watching_writable = false;
    line.feed(ev::Writable{});
    CHECK(line.take_written() == read_request);
    CHECK(line.core.master().state() == fe::MasterState::awaiting_reply);
    line.advance(1ms);
    line.arrive(reply_1());
    CHECK(line.recorder.status("poll") == OutcomeStatus::ok);
}

TEST_CASE("line core: a reply already in the driver's buffer is read before the timeout is judged") {
    // The reply timer can run after the reply deadline, before the port's readiness
    // handler (a loop held up): it must read first.
    FakeLine line;
    line.start();
    send_read(line, "poll", Priority::poll, false);
    line.now += 1s;  // the loop was held up: no timer ran
    line.input.push_back(reply_1());
    REQUIRE(line.lazy_at);
    const unsigned reads_before = line.reads;
    line.lazy_at.reset();
    line.feed(ev::TimerFired{fe::WakeTimer::lazy});
    CHECK(line.reads > reads_before);
    CHECK(line.recorder.status("poll") == OutcomeStatus::ok);
}

TEST_CASE("line core: a submission while the line waits asks no drive and no read; one while idle goes at once") {
    FakeLine line;
    line.start();
    send_read(line, "first");
    unsigned reads = line.reads;

    // Waiting for the reply: the submission joins the queue, nothing else happens.
    line.submit(read_tx(1, 2, Priority::poll), "during-reply");
    CHECK_FALSE(line.drive_posted);
    CHECK(line.core.scheduler().queued() == 1);
    line.advance(1ms);
    CHECK(line.reads == reads);
    CHECK(line.written.empty());

    // The silence after the reply, on its timer: the same.
    line.arrive(reply_1());
    CHECK(line.reads == reads + 1);
    REQUIRE(line.exact_at);
    const TimePoint silence_end = *line.exact_at;
    line.submit(read_tx(0, 1, Priority::poll), "during-silence");
    CHECK_FALSE(line.drive_posted);
    line.advance_to(silence_end);
    CHECK(line.reads == reads + 1);  // the timer's pass writes without a read
    CHECK(line.last_write_at == silence_end);
    CHECK(line.take_written().front() == 2);  // the older of the two
    line.advance(1ms);
    line.arrive(read_reply(2, {7, 8}));
    REQUIRE(line.exact_at);
    line.advance_to(*line.exact_at);
    CHECK(line.take_written() == read_request);
    line.advance(1ms);
    line.arrive(reply_1());
    CHECK(line.recorder.status("during-reply") == OutcomeStatus::ok);
    CHECK(line.recorder.status("during-silence") == OutcomeStatus::ok);

    // Idle, nothing queued: a command needs the drive, and goes at once.
    line.advance(50ms);
    line.submit(write_tx(0, 1, 0x0601, 1), "idle-command");
    CHECK(line.drive_posted);
    const TimePoint submitted_at = line.now;
    line.advance(0ms);
    const Bytes written = line.take_written();
    REQUIRE(written.size() > 2);
    CHECK(written[1] == fp::fc::write_single_register);
    CHECK(line.last_write_at == submitted_at);
}

TEST_CASE("line core: a command submitted in the silence after a reply goes before the read already queued") {
    FakeLine line;
    line.start();
    send_read(line, "first");
    line.submit(read_tx(1, 2, Priority::poll), "queued-read");
    line.advance(1ms);
    line.arrive(reply_1());
    REQUIRE(line.recorder.status("first") == OutcomeStatus::ok);
    REQUIRE(line.exact_at);
    // Nothing is picked while the silence runs.
    CHECK_FALSE(line.core.master().busy());
    line.now += 100us;  // within the 304 us silence
    line.submit(write_tx(0, 1, 0x0601, 1), "command");
    line.advance(1ms);
    const Bytes next = line.take_written();
    REQUIRE(next.size() > 2);
    CHECK(next[0] == 1);
    CHECK(next[1] == fp::fc::write_single_register);
    CHECK(line.recorder.calls("queued-read") == 0);
}

TEST_CASE("line core: after a readiness report or a timer the write needs no read; a posted drive reads first") {
    FakeLine line;
    line.start();
    send_read(line, "first");
    unsigned reads = line.reads;

    // The reply: one read for the readiness report; the next request waits for the
    // silence on the exact timer and goes without another read.
    line.submit(read_tx(0, 1, Priority::poll), "second");
    line.advance(0ms);
    reads = line.reads;
    line.arrive(reply_1());
    CHECK(line.reads == reads + 1);
    REQUIRE(line.exact_at);
    line.advance_to(*line.exact_at);
    CHECK(line.take_written() == read_request);
    CHECK(line.reads == reads + 1);

    // A posted drive with a write due reads before it writes.
    line.arrive(reply_1());
    line.now += 10ms;
    reads = line.reads;
    line.submit(read_tx(0, 1, Priority::poll), "third");
    line.advance(0ms);
    CHECK(line.take_written() == read_request);
    CHECK(line.reads == reads + 1);
}

TEST_CASE("line core: the port is read until the buffer is not full") {
    FakeLine line;
    line.start();
    send_read(line, "poll");
    const Bytes reply = reply_1();
    line.input.push_back(Bytes(reply.begin(), reply.begin() + 4));
    line.input.push_back(Bytes(reply.begin() + 4, reply.end()));
    const unsigned reads = line.reads;
    line.feed(ev::Readable{});
    CHECK(line.reads == reads + 2);
    CHECK(line.recorder.status("poll") == OutcomeStatus::ok);
}

TEST_CASE("line core: reply timeouts share the lazy timer; it is not re-set per request") {
    FakeLine line;
    line.start();
    for (int i = 0; i < 4; ++i) {
        line.submit(read_tx(0, 1, Priority::on_demand), "read" + std::to_string(i));
        line.advance(1ms);
        REQUIRE(line.take_written() == read_request);
        line.arrive(reply_1());
    }
    CHECK(line.lazy_sets == 1);  // the first reply wait; later ones find it due earlier
    send_read(line, "lost", Priority::on_demand, false);
    const TimePoint written_at = line.last_write_at;
    line.advance(1s);
    REQUIRE(line.recorder.calls("lost") == 1);
    CHECK(line.recorder.status("lost") == OutcomeStatus::timeout);
    // Judged at its deadline (the end of the request on the wire + 100 ms), not on a
    // stale early wake-up a whole timeout later.
    const auto judged = line.recorder.outcome("lost").finished - written_at;
    CHECK(judged == line.core.master().timing().wire_time(read_request.size()) + 100ms);
}

TEST_CASE("line core: an answer nobody asked for is a shell bug") {
    FakeLine line;
    CHECK_THROWS_AS(line.feed(ev::Written{}), std::logic_error);
    line.start();
    line.submit(read_tx(0, 1, Priority::poll), "poll");
    CHECK_THROWS_AS(line.feed(ev::BytesRead{}), std::logic_error);
}

}  // namespace
