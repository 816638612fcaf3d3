// LineCore's precise silence timing (LineCoreConfig::spin_lead) on the fake clock of
// line_core_fake.hpp: the early wake, the pick there, the spin to the instant, a byte
// during the spin, and what stays on the timers.
#include <doctest/doctest.h>

#include <utility>

#include "line_core_fake.hpp"

namespace {

using namespace line_core_test;

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
