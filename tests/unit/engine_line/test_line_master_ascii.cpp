// LineMaster with the WTEC-485 vendor ASCII protocol (seed 003): frames from '>' to
// CR LF, the 50 ms frame and 5 ms inter-character timeouts, the `E` not-homed echo.
// Frames from the manual's examples (tests/vectors/vectors.yaml).
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "line_test_support.hpp"

namespace {

using namespace line_test;
using fe::OutcomeStatus;

const Bytes query_grip_request = text_bytes(">01dB819\r\n");
const Bytes query_grip_reply = text_bytes(">01d0136DE\r\n");     // state 01: reached
const Bytes grip_request = text_bytes(">01E14EA0\r\n");           // E action 1 (grip)
const Bytes running_reply = text_bytes(">01IFFFFFFFD031054786\r\n");

struct AsciiSent {
    fe::LineMaster master;
    TimePoint written;
    TimePoint tx_end;
    Bytes request;

    explicit AsciiSent(wtec::Command command, fe::LineTimingConfig config = default_line())
        : master("W", config) {
        master.reset(t0);
        request = send(master, ascii_tx(0, 1, std::move(command)), t0, written);
        tx_end = written + master.timing().wire_time(request.size());
    }
};

TEST_CASE("ascii: a `d` query and its reply") {
    AsciiSent s(wtec::QueryGripState{});
    CHECK(s.request == query_grip_request);
    s.master.on_bytes(query_grip_reply, s.tx_end + 2ms);
    auto done = expect_finished(s.master, s.tx_end + 2ms);
    CHECK(done.outcome.status == OutcomeStatus::ok);
    const auto& reply = std::get<wtec::Reply>(done.outcome.reply);
    CHECK(std::get<wtec::StateCode>(reply).code == wtec::grip_state::reached);
    CHECK(s.master.counters().replies == 1);
}

TEST_CASE("ascii: the reply wait is the manual's 50 ms frame timeout, not the RTU one") {
    fe::LineTimingConfig config;
    config.response_timeout = 300ms;
    AsciiSent s(wtec::QueryGripState{}, config);
    CHECK(expect_wait(s.master, s.written) == s.tx_end + 50ms);
    CHECK(expect_finished(s.master, s.tx_end + 50ms).outcome.status == OutcomeStatus::timeout);
}

TEST_CASE("ascii: the 5 ms inter-character timeout drops an unfinished frame") {
    AsciiSent s(wtec::ReadRunning{});
    const Bytes head(running_reply.begin(), running_reply.begin() + 10);
    const TimePoint last = s.tx_end + 1ms;
    s.master.on_bytes(head, last);
    CHECK(expect_wait(s.master, last) == last + 5ms);
    CHECK(expect_wait(s.master, last + 5ms) == s.tx_end + 50ms);  // dropped, still waiting
    CHECK(s.master.counters().garbage_bytes == head.size());
    // The rest arriving late is no frame on its own.
    s.master.on_bytes(Bytes(running_reply.begin() + 10, running_reply.end()), last + 6ms);
    CHECK(expect_finished(s.master, s.tx_end + 50ms).outcome.status == OutcomeStatus::timeout);
}

TEST_CASE("ascii: a reply split into single characters, 1 ms apart") {
    AsciiSent s(wtec::ReadRunning{});
    TimePoint at = s.tx_end;
    for (const auto c : running_reply) s.master.on_bytes(Bytes{c}, at += 1ms);
    auto done = expect_finished(s.master, at);
    REQUIRE(done.outcome.status == OutcomeStatus::ok);
    const auto& running = std::get<wtec::RunningValues>(std::get<wtec::Reply>(done.outcome.reply));
    CHECK(running.position == -3);
    CHECK(running.state == wtec::grip_state::released_to_limit);
}

TEST_CASE("ascii: garbage before '>' is skipped and counted") {
    AsciiSent s(wtec::QueryGripState{});
    s.master.on_bytes(concat({Bytes{0x00, 0xFF, 0x7A, 0x7A}, query_grip_reply}), s.tx_end + 2ms);
    CHECK(expect_finished(s.master, s.tx_end + 2ms).outcome.status == OutcomeStatus::ok);
    CHECK(s.master.counters().garbage_bytes == 4);
}

TEST_CASE("ascii: a bad CRC and another station's reply are dropped and counted") {
    AsciiSent s(wtec::QueryGripState{});
    Bytes corrupted = query_grip_reply;
    corrupted[5] = '2';  // state 02 with the CRC of 01
    s.master.on_bytes(corrupted, s.tx_end + 2ms);
    CHECK(s.master.counters().crc_errors == 1);
    s.master.on_bytes(ascii_frame(2, 'd', "01"), s.tx_end + 4ms);  // station 02 answering
    CHECK(s.master.counters().wrong_address == 1);
    CHECK(s.master.state() == fe::MasterState::awaiting_reply);
    s.master.on_bytes(query_grip_reply, s.tx_end + 6ms);
    CHECK(expect_finished(s.master, s.tx_end + 6ms).outcome.status == OutcomeStatus::ok);
}

TEST_CASE("ascii: `E` answered by its own request frame means not homed") {
    AsciiSent s(wtec::GripperAction{wtec::GripAction::grip});
    CHECK(s.request == grip_request);
    s.master.on_bytes(grip_request, s.tx_end + 2ms);
    auto done = expect_finished(s.master, s.tx_end + 2ms);
    CHECK(done.outcome.status == OutcomeStatus::ok);
    CHECK(std::holds_alternative<wtec::NotExecuted>(std::get<wtec::Reply>(done.outcome.reply)));
}

TEST_CASE("ascii: with local echo, the echo of `E` is discarded and the second copy is the reply") {
    fe::LineTimingConfig config;
    config.local_echo = true;
    SUBCASE("not homed") {
        AsciiSent s(wtec::GripperAction{wtec::GripAction::grip}, config);
        s.master.on_bytes(grip_request, s.tx_end);  // our own echo
        CHECK(s.master.state() == fe::MasterState::awaiting_reply);
        CHECK(std::holds_alternative<fe::line_action::Wait>(s.master.next_action(s.tx_end)));
        s.master.on_bytes(grip_request, s.tx_end + 3ms);  // the device: same bytes
        auto done = expect_finished(s.master, s.tx_end + 3ms);
        CHECK(std::holds_alternative<wtec::NotExecuted>(std::get<wtec::Reply>(done.outcome.reply)));
    }
    SUBCASE("homed: an empty acknowledgement") {
        AsciiSent s(wtec::GripperAction{wtec::GripAction::grip}, config);
        s.master.on_bytes(concat({grip_request, ascii_frame(1, 'E', "")}), s.tx_end + 3ms);
        auto done = expect_finished(s.master, s.tx_end + 3ms);
        CHECK(std::holds_alternative<wtec::Ack>(std::get<wtec::Reply>(done.outcome.reply)));
        CHECK(s.master.counters().echo_mismatch == 0);
    }
}

TEST_CASE("ascii: a broadcast to station 00 is not answered and settles") {
    auto master = fe::LineMaster("W", default_line());
    master.reset(t0);
    TimePoint written;
    const Bytes request = send(master, ascii_tx(fe::broadcast_device, 0, wtec::Home{}), t0, written);
    CHECK(std::string(request.begin(), request.begin() + 4) == ">00G");
    const TimePoint settled =
        written + master.timing().wire_time(request.size()) + master.timing().t3_5() + master.config().broadcast_delay;
    CHECK(expect_wait(master, written) == settled);
    CHECK(expect_finished(master, settled).outcome.status == OutcomeStatus::broadcast_sent);
}

}  // namespace
