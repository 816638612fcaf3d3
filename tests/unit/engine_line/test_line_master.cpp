// LineMaster: silence, turnaround and delay before every request, deadlines, the reply
// and response timeouts, local echo, broadcasts, the state machine contract (product
// spec section 3, rules 1, 9, 11). Frames from the XEG manual (seed 001, appendix 1).
#include <doctest/doctest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "line_test_support.hpp"

namespace {

using namespace line_test;
using fe::OutcomeStatus;
using std::chrono::nanoseconds;

constexpr nanoseconds t35{303'820};

/// FC06 to XEG id 2; the reply of FC06 echoes the request byte for byte.
Transaction write_register(std::uint16_t reg = 0x0601, std::uint16_t value = 1) {
    return write_tx(0, 2, reg, value);
}

fe::LineMaster make_master(fe::LineTimingConfig config = default_line(), fe::LogSink log = {}) {
    fe::LineMaster master("A", config, std::move(log));
    master.reset(t0);
    return master;
}

TEST_CASE("master: the request waits for t3.5 of silence after the port opened") {
    auto master = make_master();
    CHECK_FALSE(master.busy());
    CHECK(std::holds_alternative<fe::line_action::Idle>(master.next_action(t0)));
    master.start(read_model(), t0);
    CHECK(master.busy());
    CHECK(master.state() == fe::MasterState::waiting_silence);
    CHECK(expect_wait(master, t0) == t0 + t35);
    CHECK(expect_wait(master, t0 + t35 - 1ns) == t0 + t35);
    CHECK(expect_write(master, t0 + t35) == read_model_request);
    CHECK(master.state() == fe::MasterState::sending);
    // Until on_written, the same Write again (the worker may still be writing).
    CHECK(expect_write(master, t0 + t35 + 10us) == read_model_request);
}

TEST_CASE("master: a read and its reply") {
    auto master = make_master();
    TimePoint written;
    send(master, read_model(), t0, written);
    CHECK(master.state() == fe::MasterState::awaiting_reply);
    const TimePoint tx_end = written + master.timing().wire_time(8);
    CHECK(expect_wait(master, written) == tx_end + 100ms);
    const TimePoint replied = tx_end + 1ms + 7 * tc;
    master.on_bytes(read_model_reply, replied);
    auto done = expect_finished(master, replied);
    CHECK(done.outcome.status == OutcomeStatus::ok);
    CHECK(done.outcome.attempts == 1);
    CHECK(done.outcome.finished == replied);
    CHECK(done.transaction.attempts == 1);
    const auto& response = std::get<fp::Response>(done.outcome.reply);
    CHECK(std::get<fp::ReadRegistersResponse>(response).values == std::vector<std::uint16_t>{0x0A20});
    CHECK_FALSE(master.busy());
    const auto& c = master.counters();
    CHECK(c.requests == 1);
    CHECK(c.replies == 1);
    CHECK(c.timeouts == 0);
    CHECK(c.bytes_tx == 8);
    CHECK(c.bytes_rx == 7);
    CHECK(c.garbage_bytes == 0);
    CHECK(c.busy_time == replied - t0);
    CHECK(master.latency().count() == 1);
    CHECK(master.latency().max() == replied - t0);
}

TEST_CASE("master: no reply times out at end of transmission + response_timeout") {
    auto master = make_master();
    TimePoint written;
    send(master, read_model(), t0, written);
    const TimePoint deadline = written + master.timing().wire_time(8) + 100ms;
    CHECK(expect_wait(master, written + 50ms) == deadline);
    CHECK(expect_wait(master, deadline - 1ns) == deadline);
    auto done = expect_finished(master, deadline);
    CHECK(done.outcome.status == OutcomeStatus::timeout);
    CHECK(done.outcome.attempts == 1);
    CHECK(master.counters().timeouts == 1);
    CHECK(master.counters().replies == 0);
}

TEST_CASE("master: reply_decision_at is when the wait for a reply can end without new bytes") {
    auto master = make_master();
    TimePoint written;
    send(master, read_model(), t0, written);
    const TimePoint deadline = written + master.timing().wire_time(8) + 100ms;
    // Nothing received: the response timeout; before it next_action() only waits.
    CHECK(master.reply_decision_at() == deadline);
    CHECK(expect_wait(master, deadline - 1ms) == master.reply_decision_at());
    // Part of a reply: the byte timeout after its last byte (5 ms by default).
    const TimePoint first = written + master.timing().wire_time(8) + 1ms;
    master.on_bytes(fp::ByteView(read_model_reply).first(3), first);
    CHECK(master.reply_decision_at() == first + 5ms);
    CHECK(expect_wait(master, first + 1ms) == master.reply_decision_at());
    // The gap passed: the partial frame is dropped, the wait goes on to the timeout.
    CHECK(expect_wait(master, first + 5ms) == deadline);
    CHECK(master.reply_decision_at() == deadline);
}

TEST_CASE("master: the next request waits for the turnaround guard after a reply") {
    fe::LineTimingConfig config;
    config.turnaround = 1ms;
    auto master = make_master(config);
    TimePoint written;
    send(master, read_model(), t0, written);
    const TimePoint replied = written + 2ms;
    master.on_bytes(read_model_reply, replied);
    (void)expect_finished(master, replied);
    master.start(read_model(), replied);
    // The guard (1 ms) is longer than t3.5 (0.304 ms): they overlap, they do not add up.
    CHECK(expect_wait(master, replied) == replied + 1ms);
    CHECK(expect_write(master, replied + 1ms) == read_model_request);
}

TEST_CASE("master: with no turnaround guard, t3.5 after the reply is enough") {
    fe::LineTimingConfig config;
    config.turnaround = Duration::zero();
    auto master = make_master(config);
    TimePoint written;
    send(master, read_model(), t0, written);
    const TimePoint replied = written + 2ms;
    master.on_bytes(read_model_reply, replied);
    (void)expect_finished(master, replied);
    master.start(read_model(), replied);
    CHECK(expect_wait(master, replied) == replied + t35);
}

TEST_CASE("master: the silence counts from the computed end of transmission") {
    auto master = make_master();
    TimePoint written;
    send(master, read_model(), t0, written);
    // The port took 8 bytes at `written`; the last leaves 8 tc later.
    CHECK(master.earliest_send() == written + master.timing().wire_time(8) + t35);
}

TEST_CASE("master: garbage on the line pushes the silence out, idle or waiting") {
    auto master = make_master();
    const TimePoint noise = t0 + 10ms;
    master.on_bytes(Bytes{0x00, 0xFF}, noise);
    CHECK(master.counters().garbage_bytes == 2);
    master.start(read_model(), noise + 100us);
    CHECK(expect_wait(master, noise + 100us) == noise + t35);
    const TimePoint more = noise + 200us;
    master.on_bytes(Bytes{0x55}, more);  // more noise while waiting for the silence
    CHECK(master.counters().garbage_bytes == 3);
    CHECK(expect_wait(master, noise + t35) == more + t35);
    CHECK(expect_write(master, more + t35) == read_model_request);
}

TEST_CASE("master: delay_before extends the silence before a command") {
    auto master = make_master();
    auto command = write_register();
    command.delay_before = 10ms;
    master.start(std::move(command), t0 + 1ms);
    CHECK(expect_wait(master, t0 + 1ms) == t0 + 10ms);
    // A delay shorter than t3.5 changes nothing.
    auto other = make_master();
    auto quick = write_register();
    quick.delay_before = 100us;
    other.start(std::move(quick), t0);
    CHECK(expect_wait(other, t0) == t0 + t35);
}

TEST_CASE("master: a deadline before the request could start finishes expired, never written") {
    auto master = make_master();
    auto command = write_register();
    command.delay_before = 10ms;
    command.deadline = t0 + 10ms;  // it would start exactly at the deadline: too late
    master.start(std::move(command), t0);
    auto done = expect_finished(master, t0);
    CHECK(done.outcome.status == OutcomeStatus::expired);
    CHECK(done.outcome.attempts == 0);
    CHECK(master.counters().expired == 1);
    CHECK(master.counters().requests == 0);
    CHECK(master.counters().bytes_tx == 0);
    CHECK(master.latency().count() == 0);

    auto in_time = write_register();
    in_time.delay_before = 10ms;
    in_time.deadline = t0 + 10ms + 1ns;
    master.start(std::move(in_time), t0);
    CHECK(expect_wait(master, t0) == t0 + 10ms);
    CHECK_FALSE(expect_write(master, t0 + 10ms).empty());
}

TEST_CASE("master: garbage while waiting can push a command past its deadline") {
    auto master = make_master();
    auto command = write_register();
    command.deadline = t0 + 1ms;
    master.start(std::move(command), t0);
    CHECK(expect_wait(master, t0) == t0 + t35);
    master.on_bytes(Bytes{0x00}, t0 + 900us);
    CHECK(expect_finished(master, t0 + 900us).outcome.status == OutcomeStatus::expired);
}

TEST_CASE("master: local echo is discarded before the reply (FC06 echo equals the reply)") {
    fe::LineTimingConfig config;
    config.local_echo = true;
    auto master = make_master(config);
    TimePoint written;
    const Bytes request = send(master, write_register(0x0601, 1), t0, written);
    CHECK(master.state() == fe::MasterState::discarding_echo);
    master.on_bytes(request, written + 8 * tc);  // the adapter echoes our own bytes
    CHECK(master.state() == fe::MasterState::awaiting_reply);
    CHECK(std::holds_alternative<fe::line_action::Wait>(master.next_action(written + 8 * tc)));
    master.on_bytes(request, written + 2ms);  // the device's reply: identical bytes
    auto done = expect_finished(master, written + 2ms);
    CHECK(done.outcome.status == OutcomeStatus::ok);
    const auto& response = std::get<fp::Response>(done.outcome.reply);
    CHECK(std::get<fp::WriteSingleResponse>(response) == fp::WriteSingleResponse{0x06, 0x0601, 1});
    CHECK(master.counters().echo_mismatch == 0);
    CHECK(master.counters().garbage_bytes == 0);
    CHECK(master.counters().bytes_rx == 16);
}

TEST_CASE("master: echo arriving before on_written, and echo + reply in one read") {
    fe::LineTimingConfig config;
    config.local_echo = true;
    auto master = make_master(config);
    master.start(read_model(), t0);
    const Bytes request = expect_write(master, t0 + t35);
    master.on_bytes(Bytes(request.begin(), request.begin() + 5), t0 + t35 + 1us);  // still sending
    master.on_written(t0 + t35 + 2us);
    CHECK(master.state() == fe::MasterState::discarding_echo);
    master.on_bytes(concat({Bytes(request.begin() + 5, request.end()), read_model_reply}), t0 + 3ms);
    auto done = expect_finished(master, t0 + 3ms);
    CHECK(done.outcome.status == OutcomeStatus::ok);
    CHECK(master.counters().echo_mismatch == 0);
}

TEST_CASE("master: an echo that differs from the request is counted; the reply still counts") {
    fe::LineTimingConfig config;
    config.local_echo = true;
    std::vector<std::string> warnings;
    auto master = make_master(config, fe::LogSink{[&](fe::LogLevel level, std::string_view m) {
                                                       if (level == fe::LogLevel::warning) warnings.emplace_back(m);
                                                   },
                                                   fe::LogLevel::info});
    TimePoint written;
    Bytes echo = send(master, read_model(), t0, written);
    echo[3] ^= 0x10;  // one bit flipped on the way back
    master.on_bytes(echo, written + 1ms);
    master.on_bytes(read_model_reply, written + 3ms);
    CHECK(expect_finished(master, written + 3ms).outcome.status == OutcomeStatus::ok);
    CHECK(master.counters().echo_mismatch == 1);
    REQUIRE(warnings.size() == 1);
    CHECK(warnings[0].find("line A #0 device 0 address 0x02: local echo differs") == 0);
}

TEST_CASE("master: a missing echo ends in a timeout") {
    fe::LineTimingConfig config;
    config.local_echo = true;
    auto master = make_master(config);
    TimePoint written;
    send(master, read_model(), t0, written);
    const TimePoint deadline = written + master.timing().wire_time(8) + 100ms;
    CHECK(expect_wait(master, written) == deadline);
    CHECK(expect_finished(master, deadline).outcome.status == OutcomeStatus::timeout);
}

TEST_CASE("master: a broadcast is written, the line settles, no reply is awaited") {
    auto master = make_master();
    auto broadcast = write_tx(fe::broadcast_device, fp::modbus_broadcast_address, 0x0620, 1);
    TimePoint written;
    const Bytes request = send(master, std::move(broadcast), t0, written);
    CHECK(request.front() == 0x00);
    CHECK(master.state() == fe::MasterState::settling_broadcast);
    const TimePoint settled = written + master.timing().wire_time(request.size()) + t35 + master.config().broadcast_delay;
    CHECK(expect_wait(master, written) == settled);
    master.on_bytes(Bytes{0x00, 0x06}, written + 1ms);  // nobody answers a broadcast: noise
    CHECK(expect_wait(master, written + 1ms) == settled);
    auto done = expect_finished(master, settled);
    CHECK(done.outcome.status == OutcomeStatus::broadcast_sent);
    CHECK(done.outcome.attempts == 1);
    CHECK(master.counters().broadcasts == 1);
    CHECK(master.counters().requests == 0);
    CHECK(master.counters().garbage_bytes == 2);
}

TEST_CASE("master: the EXCD203MB broadcast address 0xFF; echo of a broadcast is not garbage") {
    fe::LineTimingConfig config;
    config.local_echo = true;
    auto master = make_master(config);
    auto broadcast = write_tx(fe::broadcast_device, fp::excd_broadcast_address, 0x0100, 1);
    TimePoint written;
    const Bytes request = send(master, std::move(broadcast), t0, written);
    CHECK(request.front() == 0xFF);
    master.on_bytes(request, written + 1ms);
    const TimePoint settled = written + master.timing().wire_time(request.size()) + t35 + master.config().broadcast_delay;
    CHECK(expect_finished(master, settled).outcome.status == OutcomeStatus::broadcast_sent);
    CHECK(master.counters().garbage_bytes == 0);
    CHECK(master.counters().echo_mismatch == 0);
}

TEST_CASE("master: a request the codec refuses finishes invalid_request, never written") {
    std::vector<std::string> errors;
    auto master = make_master(default_line(), fe::LogSink{[&](fe::LogLevel level, std::string_view m) {
                                                              if (level == fe::LogLevel::error) errors.emplace_back(m);
                                                          },
                                                          fe::LogLevel::info});
    master.start(read_tx(0, 2, Priority::poll, 0x0300, 0), t0);  // a count of 0 cannot be encoded
    auto done = expect_finished(master, t0);
    CHECK(done.outcome.status == OutcomeStatus::invalid_request);
    CHECK(done.outcome.attempts == 0);
    CHECK(master.counters().bytes_tx == 0);
    REQUIRE(errors.size() == 1);
    CHECK(errors[0].find("cannot be encoded") != std::string::npos);
    CHECK_FALSE(master.busy());
}

TEST_CASE("master: contract violations are refused loudly") {
    auto master = make_master();
    CHECK_THROWS_AS(master.on_written(t0), std::logic_error);
    master.start(read_model(), t0);
    CHECK_THROWS_WITH_AS(master.start(read_model(), t0), doctest::Contains("in flight"), std::logic_error);
    CHECK_THROWS_AS(master.on_written(t0), std::logic_error);  // no Write handed out yet
}

TEST_CASE("master: abort hands the transaction back with what may have happened") {
    auto master = make_master();
    CHECK_FALSE(master.abort(t0).has_value());

    master.start(read_model(), t0);
    auto before = master.abort(t0);
    REQUIRE(before.has_value());
    CHECK(before->outcome.status == OutcomeStatus::line_down);
    CHECK_FALSE(master.busy());

    TimePoint written;
    send(master, write_register(), t0 + 1ms, written);
    auto after = master.abort(written + 1ms);
    REQUIRE(after.has_value());
    CHECK(after->outcome.status == OutcomeStatus::timeout);  // the device may have acted
    CHECK(after->outcome.attempts == 1);

    send(master, write_tx(fe::broadcast_device, 0, 0x0620, 1), written + 1s, written);
    auto broadcast = master.abort(written);
    REQUIRE(broadcast.has_value());
    CHECK(broadcast->outcome.status == OutcomeStatus::broadcast_sent);

    master.start(read_model(), written + 2s);
    (void)expect_write(master, written + 2s);  // handed to the port, on_written never came
    auto partial = master.abort(written + 2s);
    REQUIRE(partial.has_value());
    CHECK(partial->outcome.status == OutcomeStatus::timeout);
}

TEST_CASE("master: every transition is logged at debug level, and only then") {
    std::vector<std::string> lines;
    auto sink = fe::LogSink{[&](fe::LogLevel level, std::string_view m) {
                                CHECK(level == fe::LogLevel::debug);
                                lines.emplace_back(m);
                            },
                            fe::LogLevel::debug};
    auto master = make_master(default_line(), sink);
    auto t = read_model();
    t.id = 42;
    TimePoint written;
    send(master, std::move(t), t0, written);
    master.on_bytes(read_model_reply, written + 2ms);
    (void)expect_finished(master, written + 2ms);
    const std::vector<std::string> expected{
        "line A #42 device 0 address 0x02: idle -> waiting_silence (started)",
        "line A #42 device 0 address 0x02: waiting_silence -> sending (silence observed)",
        "line A #42 device 0 address 0x02: sending -> awaiting_reply (request written)",
        "line A #42 device 0 address 0x02: awaiting_reply -> complete (valid reply)",
        "line A #42 device 0 address 0x02: complete -> idle (ok)",
    };
    CHECK(lines == expected);

    lines.clear();
    sink.min_level = fe::LogLevel::info;
    auto quiet = make_master(default_line(), sink);
    send(quiet, read_model(), t0, written);
    CHECK(lines.empty());
}

}  // namespace
