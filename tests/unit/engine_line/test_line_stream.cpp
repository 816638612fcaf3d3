// A line behind a serial device server (a TCP stream, issue 27), in the sans-I/O
// parts: the master frames by predicted length or tcp_frame_gap and drops a late
// reply to an earlier request; the silence before a request is max(t3.5,
// request_gap); the core waits for a connect that only began (OpenPending).
#include <doctest/doctest.h>

#include <algorithm>

#include "line_core_fake.hpp"
#include "line_test_support.hpp"

namespace {

using namespace line_test;
using namespace line_core_test;
using fe::OutcomeStatus;

fe::LineTimingConfig stream_line() {
    fe::LineTimingConfig config;
    config.stream = true;
    config.frame_gap = 8ms;
    config.byte_timeout = 5ms;
    return config;
}

struct StreamSent {
    fe::LineMaster master{"T", stream_line()};
    TimePoint written;
    TimePoint tx_end;

    explicit StreamSent(fe::LineTimingConfig config = stream_line()) : master("T", config) {
        master.reset(t0);
        send(master, read_model(), t0, written);
        tx_end = written + master.timing().wire_time(read_model_request.size());
    }
};

TEST_CASE("stream: a reply split across segments is joined; the frame gap, not byte_timeout, bounds the split") {
    StreamSent s;
    const Bytes head(read_model_reply.begin(), read_model_reply.begin() + 3);
    const Bytes tail(read_model_reply.begin() + 3, read_model_reply.end());
    s.master.on_bytes(head, s.tx_end + 1ms);
    // 6 ms later: past byte_timeout (5 ms) but inside the frame gap (8 ms).
    CHECK(expect_wait(s.master, s.tx_end + 1ms) == s.tx_end + 1ms + 8ms);
    s.master.on_bytes(tail, s.tx_end + 7ms);
    auto done = expect_finished(s.master, s.tx_end + 7ms);
    CHECK(done.outcome.status == OutcomeStatus::ok);
    CHECK(s.master.counters().garbage_bytes == 0);
}

TEST_CASE("stream: a partial reply is given up after the frame gap") {
    StreamSent s;
    const Bytes head(read_model_reply.begin(), read_model_reply.begin() + 3);
    s.master.on_bytes(head, s.tx_end + 1ms);
    CHECK(expect_wait(s.master, s.tx_end + 1ms + 8ms) > s.tx_end + 9ms);  // dropped, waits for the deadline
    CHECK(s.master.counters().garbage_bytes == 3);
}

TEST_CASE("stream: two replies in one segment: the newest is the answer, the older one is a late reply") {
    StreamSent s;
    // The device server held the reply to an earlier read of the same register (it
    // timed out) and sends it with this one's.
    const Bytes stale = read_reply(2, {0x0BAD}, fp::fc::read_holding_registers);
    s.master.on_bytes(concat({stale, read_model_reply}), s.tx_end + 1ms);
    auto done = expect_finished(s.master, s.tx_end + 1ms);
    REQUIRE(done.outcome.status == OutcomeStatus::ok);
    const auto& reply = std::get<fp::Response>(done.outcome.reply);
    CHECK(std::get<fp::ReadRegistersResponse>(reply).values == std::vector<std::uint16_t>{0x0A20});
    CHECK(s.master.counters().garbage_bytes == stale.size());
}

TEST_CASE("stream: a whole reply followed by the start of another waits for the newer one") {
    StreamSent s;
    const Bytes stale = read_reply(2, {0x0BAD}, fp::fc::read_holding_registers);
    const Bytes head(read_model_reply.begin(), read_model_reply.begin() + 2);
    const Bytes tail(read_model_reply.begin() + 2, read_model_reply.end());
    s.master.on_bytes(concat({stale, head}), s.tx_end + 1ms);
    CHECK(s.master.state() == fe::MasterState::awaiting_reply);
    s.master.on_bytes(tail, s.tx_end + 2ms);
    auto done = expect_finished(s.master, s.tx_end + 2ms);
    REQUIRE(done.outcome.status == OutcomeStatus::ok);
    CHECK(std::get<fp::ReadRegistersResponse>(std::get<fp::Response>(done.outcome.reply)).values ==
          std::vector<std::uint16_t>{0x0A20});
}

TEST_CASE("stream: bytes before the request can have crossed the far side's line are a late reply, dropped") {
    StreamSent s;
    // The late reply to an earlier read of the same register arrives right after the
    // write: on the far side the request is still on the wire, so it cannot answer it.
    const Bytes stale = read_reply(2, {0x0BAD}, fp::fc::read_holding_registers);
    s.master.on_bytes(stale, s.written + 100us);
    CHECK(s.master.state() == fe::MasterState::awaiting_reply);
    CHECK(s.master.counters().garbage_bytes == stale.size());
    CHECK(expect_wait(s.master, s.written + 100us) == s.tx_end + stream_line().response_timeout);
    s.master.on_bytes(read_model_reply, s.tx_end + 2ms);
    auto done = expect_finished(s.master, s.tx_end + 2ms);
    REQUIRE(done.outcome.status == OutcomeStatus::ok);
    const auto& reply = std::get<fp::Response>(done.outcome.reply);
    CHECK(std::get<fp::ReadRegistersResponse>(reply).values == std::vector<std::uint16_t>{0x0A20});
}

TEST_CASE("stream: on a serial line the same early bytes are framed (no stream rule there)") {
    fe::LineTimingConfig serial = stream_line();
    serial.stream = false;
    StreamSent s(serial);
    s.master.on_bytes(read_model_reply, s.written + 100us);
    CHECK(expect_finished(s.master, s.written + 100us).outcome.status == OutcomeStatus::ok);
}

TEST_CASE("request_gap: the silence before a request is max(t3.5, request_gap)") {
    fe::LineTimingConfig config = stream_line();
    SUBCASE("shorter than t3.5: t3.5 stands") {
        config.request_gap = 100us;
        fe::LineMaster master("T", config);
        master.reset(t0);
        master.start(read_model(), t0);
        CHECK(expect_wait(master, t0) == t0 + master.timing().t3_5());
    }
    SUBCASE("longer: the gap") {
        config.request_gap = 3ms;
        fe::LineMaster master("T", config);
        master.reset(t0);
        master.start(read_model(), t0);
        CHECK(expect_wait(master, t0) == t0 + 3ms);
        CHECK(expect_write(master, t0 + 3ms) == read_model_request);
    }
}

TEST_CASE("line core: a connect that only began leaves the line down until Opened comes as an event") {
    FakeLine line;
    line.open_pending = true;
    line.start();
    CHECK_FALSE(line.core.line_up());
    CHECK(line.states.empty());
    // Submissions before the first open queue, as for a tty.
    line.submit(read_tx(0, 1, Priority::poll), "early");
    line.advance(1ms);
    CHECK(line.written.empty());
    line.feed(ev::Opened{"connected to 127.0.0.1:4001"});
    CHECK(line.core.line_up());
    CHECK(line.states == std::vector<bool>{true});
    CHECK(line.logged(fe::LogLevel::info, "line L: /dev/ttyFAKE open, connected to 127.0.0.1:4001"));
    line.advance(1ms);
    CHECK(line.take_written() == read_request);
}

TEST_CASE("line core: a connect that fails later goes down and is retried on the back-off") {
    FakeLine line;
    line.open_pending = true;
    line.start();
    line.feed(ev::OpenFailed{"tcp://127.0.0.1:4001: cannot connect (Connection refused)"});
    CHECK(line.states == std::vector<bool>{false});
    CHECK(line.logged(fe::LogLevel::error, "cannot open /dev/ttyFAKE: tcp://127.0.0.1:4001: cannot connect"));
    REQUIRE(line.reopen_at == t0 + 100ms);
    line.open_pending = false;
    line.advance_to(t0 + 100ms);
    CHECK(line.core.line_up());
    CHECK(line.core.reopens() == 1);
}

TEST_CASE("line core: at the maximum back-off a repeated failure is logged once a minute, with a count") {
    FakeLine line;  // reopen back-off 100 ms doubling to 350 ms
    line.open_failure = "tcp://10.0.0.7:4001: cannot connect to 10.0.0.7:4001 (Connection refused)";
    line.start();
    const auto reopen_lines = [&] {
        return std::count_if(line.logs.begin(), line.logs.end(), [](const auto& entry) {
            return entry.first == fe::LogLevel::warning && entry.second.find("reopening") != std::string::npos;
        });
    };
    line.advance_to(t0 + 30s);  // about 85 attempts
    CHECK(reopen_lines() == 2);  // 200 ms, then the first at the maximum (350 ms)
    line.advance_to(t0 + 62s);
    CHECK(reopen_lines() == 3);
    CHECK(line.logged(fe::LogLevel::warning, "more failures like it since the last such line)"));
    // Another failure is logged at once.
    line.open_failure = "tcp://10.0.0.7:4001: no answer within 2000 ms (connect_timeout)";
    line.advance(400ms);
    CHECK(reopen_lines() == 4);
}

TEST_CASE("line core: Stop during a connect; the connect's late end is ignored") {
    FakeLine line;
    line.open_pending = true;
    line.start();
    line.feed(ev::Stop{});
    line.feed(ev::Opened{"late"});
    CHECK_FALSE(line.core.line_up());
    CHECK(line.core.stopped());
}

TEST_CASE("line core: an Opened nobody waits for is a shell bug") {
    FakeLine line;
    line.start();
    CHECK_THROWS_AS(line.feed(ev::Opened{"twice"}), std::logic_error);
}

}  // namespace
