// LineCore with a fake clock and a scripted port: the worker's behaviours that need
// no I/O (reopen back-off, line down and up, stop, completions exactly once and a
// submit from one, expiry, blocked writes, reading before a decision, the two wake
// timers). The shell here answers the core's questions the way the line worker does.
#include <doctest/doctest.h>

#include <deque>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "line_test_support.hpp"

namespace {

using namespace line_test;
using fe::OutcomeStatus;
namespace ev = fe::line_event;

struct FakeLine {
    explicit FakeLine(fe::LineCoreConfig config = named("L"))
        : core(std::move(config), "/dev/ttyFAKE", sink()), delivery("L", sink()) {
        core.scheduler().add_device(0, fe::DeviceLimits{});
        core.scheduler().add_device(1, fe::DeviceLimits{});
    }
    static fe::LineCoreConfig named(std::string name) {
        fe::LineCoreConfig config;
        config.name = std::move(name);
        config.reopen_initial = 100ms;
        config.reopen_max = 350ms;
        return config;
    }
    fe::LogSink sink() {
        return fe::LogSink{[this](fe::LogLevel level, std::string_view m) { logs.emplace_back(level, m); },
                           fe::LogLevel::info};
    }
    [[nodiscard]] bool logged(fe::LogLevel level, const std::string& text) const {
        for (const auto& [l, m] : logs) {
            if (l == level && m.find(text) != std::string::npos) return true;
        }
        return false;
    }

    // ---- the shell ----------------------------------------------------------------

    void feed(fe::LineEvent&& event) {
        while (true) {
            const fe::LineStep step = core.handle(now, std::move(event));
            if (step.close_port) ++closes;
            if (step.cancel_timers) exact_at = lazy_at = reopen_at = std::nullopt;
            if (step.exact_wake) {
                exact_at = step.exact_wake;
                ++exact_sets;
            }
            if (step.lazy_wake) {
                lazy_at = step.lazy_wake;
                ++lazy_sets;
            }
            if (step.reopen_at) reopen_at = step.reopen_at;
            if (step.watch_writable) watching_writable = true;
            if (step.post_drive) drive_posted = true;
            delivery.deliver(core.scheduler());
            if (step.line_up) states.push_back(*step.line_up);
            switch (step.next) {
                case fe::LineNext::none: return;
                case fe::LineNext::resume:
                case fe::LineNext::tick: event = ev::Resume{}; break;
                case fe::LineNext::spin:
                    // The clock seam runs on while the shell spins; bytes may arrive.
                    ++spins;
                    REQUIRE(step.spin_until > now);
                    REQUIRE(step.spin_until - now <= core.config().spin_lead);
                    now = step.spin_until;
                    for (Bytes& bytes : arrive_during_spin) input.push_back(std::move(bytes));
                    arrive_during_spin.clear();
                    event = ev::Resume{};
                    break;
                case fe::LineNext::open:
                    if (open_failure) {
                        event = ev::OpenFailed{*open_failure};
                    } else {
                        event = ev::Opened{"low latency: test"};
                    }
                    break;
                case fe::LineNext::read: event = read(); break;
                case fe::LineNext::write: event = write(step.write); break;
            }
        }
    }

    fe::LineEvent read() {
        ++reads;
        if (read_failure) return ev::PortFailed{"read", *read_failure};
        read_buffer.clear();
        if (!input.empty()) {
            read_buffer = input.front();
            input.pop_front();
        }
        return ev::BytesRead{read_buffer, !input.empty() && full_reads};
    }

    fe::LineEvent write(fp::ByteView bytes) {
        const std::size_t n = std::min(bytes.size(), write_capacity);
        written.insert(written.end(), bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n));
        last_write_at = now;
        write_capacity -= n;
        if (n < bytes.size()) return ev::WriteBlocked{n};
        return ev::Written{};
    }

    /// Posted work first, then the timers due, in time order, until @p until.
    void advance_to(TimePoint until) {
        while (true) {
            if (drive_posted) {
                drive_posted = false;
                feed(ev::Drive{});
                continue;
            }
            std::optional<TimePoint> next;
            for (const auto& at : {exact_at, lazy_at, reopen_at}) {
                if (at && (!next || *at < *next)) next = at;
            }
            if (!next || *next > until) break;
            now = std::max(now, *next);
            if (exact_at == next) {
                exact_at.reset();
                feed(ev::TimerFired{fe::WakeTimer::exact});
            } else if (lazy_at == next) {
                lazy_at.reset();
                feed(ev::TimerFired{fe::WakeTimer::lazy});
            } else {
                reopen_at.reset();
                feed(ev::ReopenDue{});
            }
        }
        now = std::max(now, until);
    }
    void advance(Duration by) { advance_to(now + by); }

    void start() {
        feed(ev::Start{});
        advance(0ms);
    }
    void submit(Transaction t, const std::string& tag) {
        feed(ev::Submit{tagged(std::move(t), recorder, tag)});
    }
    /// The readiness report for bytes that arrived: one read, then a drive (polled).
    void arrive(Bytes bytes) {
        input.push_back(std::move(bytes));
        feed(ev::Readable{});
        advance(0ms);
    }
    /// The written bytes since the last call.
    Bytes take_written() { return std::exchange(written, {}); }

    TimePoint now = t0;
    std::vector<std::pair<fe::LogLevel, std::string>> logs;
    fe::LineCore core;
    fe::LineDelivery delivery;
    Recorder recorder;
    std::vector<bool> states;

    std::deque<Bytes> input;  ///< what each read returns, one chunk per read
    bool full_reads = true;   ///< a read reports the buffer full while more chunks wait
    Bytes read_buffer;
    Bytes written;
    std::size_t write_capacity = std::numeric_limits<std::size_t>::max();
    std::optional<std::string> open_failure;
    std::optional<std::string> read_failure;
    TimePoint last_write_at{};
    std::vector<Bytes> arrive_during_spin;  ///< in the port's buffer once the next spin ends
    unsigned spins = 0;
    unsigned reads = 0;
    unsigned closes = 0;
    unsigned exact_sets = 0;
    unsigned lazy_sets = 0;
    bool watching_writable = false;
    bool drive_posted = false;
    std::optional<TimePoint> exact_at;
    std::optional<TimePoint> lazy_at;
    std::optional<TimePoint> reopen_at;
};

const Bytes read_request = fp::encode_rtu(
    1, fp::encode_request(fp::ReadRegistersRequest{fp::fc::read_input_registers, 0x0300, 2}));

Bytes reply_1() { return read_reply(1, {7, 8}); }

/// Submits a read of device 0 (address 1) and lets it go out.
void send_read(FakeLine& line, const std::string& tag, Priority priority = Priority::poll, bool retry = true) {
    Transaction t = read_tx(0, 1, priority);
    t.retry_allowed = retry;
    line.submit(std::move(t), tag);
    line.advance(1ms);
    REQUIRE(line.take_written() == read_request);
}

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

// ---- precise silence timing ------------------------------------------------------

fe::LineCoreConfig precise(std::uint32_t baud = 115200) {
    fe::LineCoreConfig config = FakeLine::named("L");
    config.timing.baud = baud;
    config.spin_lead = 200us;
    return config;
}

TEST_CASE("line core: precise timing wakes the spin lead before the silence ends and writes at the instant") {
    FakeLine line(precise());
    line.start();
    const fe::Duration t3_5 = line.core.master().timing().t3_5();  // 304 us at 115200
    REQUIRE(t3_5 > 200us);
    line.submit(read_tx(0, 1, Priority::poll), "first");
    line.advance(0ms);
    // The timer is set the lead early; the request is picked and encoded then.
    REQUIRE(line.exact_at == t0 + t3_5 - 200us);
    CHECK_FALSE(line.core.master().busy());
    CHECK(line.spins == 0);
    line.advance_to(t0 + t3_5 - 200us);
    CHECK(line.spins == 1);
    CHECK(line.last_write_at == t0 + t3_5);  // the spin's end, not a timer's
    CHECK(line.take_written() == read_request);

    // After the reply: the next request, already queued, the same way.
    line.submit(read_tx(1, 2, Priority::poll), "second");
    line.advance(1ms);
    const TimePoint reply_at = line.now;
    line.arrive(reply_1());
    CHECK(line.recorder.status("first") == OutcomeStatus::ok);
    CHECK(line.exact_at == reply_at + t3_5 - 200us);
    line.advance_to(reply_at + t3_5);
    CHECK(line.spins == 2);
    CHECK(line.last_write_at == reply_at + t3_5);
    CHECK_FALSE(line.take_written().empty());
}

TEST_CASE("line core: precise timing picks at the early wake: a command submitted before it goes first") {
    FakeLine line(precise());
    line.start();
    const fe::Duration t3_5 = line.core.master().timing().t3_5();
    send_read(line, "first");
    line.submit(read_tx(1, 2, Priority::poll), "queued-read");
    line.advance(1ms);
    const TimePoint reply_at = line.now;
    line.arrive(reply_1());
    REQUIRE(line.exact_at == reply_at + t3_5 - 200us);
    line.now += 50us;  // before the early wake
    line.submit(write_tx(0, 1, 0x0601, 1), "command");
    CHECK_FALSE(line.drive_posted);
    line.advance_to(reply_at + t3_5);
    CHECK(line.last_write_at == reply_at + t3_5);  // the spin's end, as before
    const Bytes next = line.take_written();
    REQUIRE(next.size() > 2);
    CHECK(next[1] == fp::fc::write_single_register);
}

TEST_CASE("line core: without precise timing the exact timer is set to the instant and nothing spins") {
    FakeLine line;
    line.start();
    const fe::Duration t3_5 = line.core.master().timing().t3_5();
    line.submit(read_tx(0, 1, Priority::poll), "first");
    line.advance(0ms);
    CHECK(line.exact_at == t0 + t3_5);
    line.advance(1ms);
    CHECK(line.spins == 0);
    CHECK(line.last_write_at == t0 + t3_5);
}

TEST_CASE("line core: precise timing spins at once when the silence is shorter than the lead (921600 bit/s)") {
    FakeLine line(precise(921600));
    line.start();
    const fe::Duration t3_5 = line.core.master().timing().t3_5();  // 38 us
    REQUIRE(t3_5 < 200us);
    line.submit(read_tx(0, 1, Priority::poll), "first");
    line.advance(0ms);
    CHECK(line.spins == 1);
    CHECK(line.exact_sets == 0);  // no timer at all
    CHECK(line.last_write_at == t0 + t3_5);
    CHECK(line.take_written() == read_request);
}

TEST_CASE("line core: a byte that arrives during the spin pushes the request out by a new silence") {
    FakeLine line(precise());
    line.start();
    const fe::Duration t3_5 = line.core.master().timing().t3_5();
    line.submit(read_tx(0, 1, Priority::poll), "first");
    line.advance(0ms);
    line.arrive_during_spin.push_back(Bytes{0x55});
    const unsigned reads_before = line.reads;
    line.advance_to(t0 + t3_5 - 200us);
    // The port is read after the spin, before the write: the stray byte is seen.
    CHECK(line.reads == reads_before + 1);
    CHECK(line.written.empty());
    CHECK(line.core.master().counters().garbage_bytes == 1);
    // The silence counts again from the byte (read at the end of the spin).
    line.advance(1ms);
    CHECK(line.spins == 2);
    CHECK(line.last_write_at == t0 + t3_5 + t3_5);
    CHECK(line.take_written() == read_request);
}

TEST_CASE("line core: precise timing leaves reply timeouts to the timers") {
    fe::LineCoreConfig config = precise();
    FakeLine line(config);
    line.start();
    send_read(line, "lost", Priority::poll, false);
    const unsigned spins = line.spins;
    line.advance(150ms);  // the 100 ms response timeout passes with no reply
    CHECK(line.recorder.status("lost") == OutcomeStatus::timeout);
    CHECK(line.spins == spins);
}

}  // namespace
