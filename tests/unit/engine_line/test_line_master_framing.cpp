// LineMaster receive path: replies framed by the predicted length, garbage ahead of a
// reply, CRC errors, replies from another slave, split replies, the byte timeout and
// the receive backstop (product spec section 3 rule 11, section 8).
#include <doctest/doctest.h>

#include <vector>

#include "line_test_support.hpp"

namespace {

using namespace line_test;
using fe::OutcomeStatus;
using std::chrono::nanoseconds;


struct Sent {
    fe::LineMaster master{"A", default_line()};
    TimePoint written;
    TimePoint tx_end;
    TimePoint reply_deadline;

    explicit Sent(Transaction t = read_model(), fe::LineTimingConfig config = default_line())
        : master("A", config) {
        master.reset(t0);
        send(master, std::move(t), t0, written);
        tx_end = written + master.timing().wire_time(8);
        reply_deadline = tx_end + config.response_timeout;
    }
};

TEST_CASE("framing: garbage ahead of a reply in the same read is skipped and counted") {
    Sent s;
    s.master.on_bytes(concat({Bytes{0x00, 0xFF, 0x13}, read_model_reply}), s.written + 2ms);
    auto done = expect_finished(s.master, s.written + 2ms);
    CHECK(done.outcome.status == OutcomeStatus::ok);
    CHECK(s.master.counters().garbage_bytes == 3);
    CHECK(s.master.counters().replies == 1);
}

TEST_CASE("framing: garbage in its own read, then the reply") {
    Sent s;
    s.master.on_bytes(Bytes{0xFF}, s.tx_end + 10us);  // a transceiver turning around
    CHECK(std::holds_alternative<fe::line_action::Wait>(s.master.next_action(s.tx_end + 20us)));
    s.master.on_bytes(read_model_reply, s.tx_end + 2ms);
    CHECK(expect_finished(s.master, s.tx_end + 2ms).outcome.status == OutcomeStatus::ok);
    CHECK(s.master.counters().garbage_bytes == 1);
}

TEST_CASE("framing: a reply with a bad CRC is dropped and counted, the valid one is taken") {
    Sent s;
    Bytes corrupted = read_model_reply;
    corrupted[4] ^= 0x01;
    s.master.on_bytes(corrupted, s.tx_end + 2ms);
    CHECK(s.master.counters().crc_errors == 1);
    CHECK(s.master.state() == fe::MasterState::awaiting_reply);
    CHECK(expect_wait(s.master, s.tx_end + 2ms) == s.reply_deadline);
    s.master.on_bytes(read_model_reply, s.tx_end + 20ms);
    auto done = expect_finished(s.master, s.tx_end + 20ms);
    CHECK(done.outcome.status == OutcomeStatus::ok);
    CHECK(s.master.counters().crc_errors == 1);
    CHECK(s.master.counters().replies == 1);
}

TEST_CASE("framing: a bad CRC alone ends in a timeout (reads are retried by the scheduler)") {
    Sent s;
    Bytes corrupted = read_model_reply;
    corrupted.back() ^= 0xFF;
    s.master.on_bytes(corrupted, s.tx_end + 2ms);
    CHECK(expect_finished(s.master, s.reply_deadline).outcome.status == OutcomeStatus::timeout);
    CHECK(s.master.counters().crc_errors == 1);
    CHECK(s.master.counters().timeouts == 1);
}

TEST_CASE("framing: a reply from the wrong slave is dropped and counted once") {
    const Bytes from_slave_3 = read_reply(3, {0x0A20}, fp::fc::read_holding_registers);
    SUBCASE("in one read") {
        Sent s;
        s.master.on_bytes(from_slave_3, s.tx_end + 2ms);
        CHECK(s.master.counters().wrong_address == 1);
        CHECK(expect_finished(s.master, s.reply_deadline).outcome.status == OutcomeStatus::timeout);
    }
    SUBCASE("one byte at a time") {
        Sent s;
        TimePoint at = s.tx_end + 2ms;
        for (const auto b : from_slave_3) s.master.on_bytes(Bytes{b}, at += tc);
        CHECK(s.master.counters().wrong_address == 1);
        CHECK(s.master.counters().garbage_bytes == from_slave_3.size());
        CHECK(expect_finished(s.master, s.reply_deadline).outcome.status == OutcomeStatus::timeout);
    }
    SUBCASE("followed by ours in the same read: skipped ahead of the reply, as garbage") {
        Sent s;
        s.master.on_bytes(concat({from_slave_3, read_model_reply}), s.tx_end + 2ms);
        CHECK(expect_finished(s.master, s.tx_end + 2ms).outcome.status == OutcomeStatus::ok);
        CHECK(s.master.counters().garbage_bytes == from_slave_3.size());
    }
    SUBCASE("two frames from other slaves, apart by more than t3.5, count twice") {
        Sent s;
        s.master.on_bytes(from_slave_3, s.tx_end + 2ms);
        s.master.on_bytes(from_slave_3, s.tx_end + 4ms);
        CHECK(s.master.counters().wrong_address == 2);
    }
}

TEST_CASE("framing: a reply split into single bytes completes on its last byte") {
    Sent s;
    TimePoint at = s.tx_end + 1ms;
    for (std::size_t i = 0; i + 1 < read_model_reply.size(); ++i) {
        s.master.on_bytes(Bytes{read_model_reply[i]}, at += tc);
        CHECK(s.master.state() == fe::MasterState::awaiting_reply);
        // While a reply is arriving, the wait is the byte timeout after the last byte.
        CHECK(expect_wait(s.master, at) == at + 5ms);
    }
    s.master.on_bytes(Bytes{read_model_reply.back()}, at += tc);
    auto done = expect_finished(s.master, at);
    CHECK(done.outcome.status == OutcomeStatus::ok);
    CHECK(s.master.counters().garbage_bytes == 0);
}

TEST_CASE("framing: the byte timeout drops an unfinished reply") {
    SUBCASE("then the response timeout ends the wait") {
        Sent s;
        const TimePoint last = s.tx_end + 2ms;
        s.master.on_bytes(Bytes(read_model_reply.begin(), read_model_reply.begin() + 3), last);
        CHECK(expect_wait(s.master, last + 1ms) == last + 5ms);
        CHECK(expect_wait(s.master, last + 5ms) == s.reply_deadline);  // dropped; waiting on
        CHECK(s.master.counters().garbage_bytes == 3);
        CHECK(expect_finished(s.master, s.reply_deadline).outcome.status == OutcomeStatus::timeout);
    }
    SUBCASE("then a whole reply is still taken") {
        Sent s;
        const TimePoint last = s.tx_end + 2ms;
        s.master.on_bytes(Bytes(read_model_reply.begin(), read_model_reply.begin() + 3), last);
        CHECK(expect_wait(s.master, last + 5ms) == s.reply_deadline);
        s.master.on_bytes(read_model_reply, last + 10ms);
        CHECK(expect_finished(s.master, last + 10ms).outcome.status == OutcomeStatus::ok);
    }
    SUBCASE("a gap after the response timeout finishes at once") {
        Sent s;
        const TimePoint last = s.reply_deadline - 1ms;
        s.master.on_bytes(Bytes(read_model_reply.begin(), read_model_reply.begin() + 3), last);
        CHECK(expect_wait(s.master, last) == last + 5ms);
        CHECK(expect_finished(s.master, last + 5ms).outcome.status == OutcomeStatus::timeout);
        CHECK(s.master.counters().garbage_bytes == 3);
    }
}

TEST_CASE("framing: a reply that started in time is not cut by the response timeout") {
    Sent s;
    TimePoint at = s.reply_deadline - 2ms;
    for (const auto b : read_model_reply) {
        s.master.on_bytes(Bytes{b}, at);
        if (s.master.state() == fe::MasterState::awaiting_reply) {
            CHECK(std::holds_alternative<fe::line_action::Wait>(s.master.next_action(at)));
        }
        at += 1ms;  // slow device: 1 ms between characters, under the 5 ms byte timeout
    }
    CHECK(expect_finished(s.master, at).outcome.status == OutcomeStatus::ok);
}

TEST_CASE("framing: an endless stream of plausible bytes is cut by the receive backstop") {
    // Function 0x41 is opaque: its reply is framed by the shortest CRC-valid prefix, so
    // bytes that start with our address keep the framer waiting.
    Transaction opaque;
    opaque.device = 0;
    opaque.address = 2;
    opaque.payload = fe::ModbusPayload{fp::OpaqueRequest{0x41, {0x01, 0x02}}};
    fe::LineTimingConfig config;
    config.response_timeout = 10ms;
    fe::LineMaster master("A", config);
    master.reset(t0);
    TimePoint written;
    const Bytes request = send(master, std::move(opaque), t0, written);
    const TimePoint tx_end = written + master.timing().wire_time(request.size());
    const TimePoint backstop = tx_end + 10ms + master.timing().wire_time(fp::max_rtu_adu_size) + 5ms;
    master.on_bytes(Bytes{0x02, 0x41}, tx_end + 1ms);  // our address, our function code
    TimePoint now = tx_end + 1ms;
    std::optional<TimePoint> finished_at;
    while (!finished_at && now < tx_end + 1s) {
        now += 1ms;
        auto action = master.next_action(now);
        if (std::holds_alternative<fe::line_action::Finished>(action)) {
            CHECK(std::get<fe::line_action::Finished>(action).outcome.status == OutcomeStatus::timeout);
            finished_at = now;
        } else {
            master.on_bytes(Bytes{0x5A}, now);  // never a gap, never a valid CRC
        }
    }
    REQUIRE(finished_at.has_value());
    CHECK(*finished_at > tx_end + 10ms);  // the stream kept it past the response timeout
    CHECK(*finished_at <= backstop + 1ms);
}

TEST_CASE("framing: a Modbus exception reply is a valid reply (XEG 0x04 is delivered)") {
    Sent s;
    const Bytes exception = rtu(2, fp::encode_exception(0x03, fp::ExceptionCode::server_device_failure));
    s.master.on_bytes(exception, s.tx_end + 2ms);
    auto done = expect_finished(s.master, s.tx_end + 2ms);
    CHECK(done.outcome.status == OutcomeStatus::ok);
    const auto& response = std::get<fp::Response>(done.outcome.reply);
    CHECK(std::get<fp::ExceptionResponse>(response) ==
          fp::ExceptionResponse{0x03, fp::ExceptionCode::server_device_failure});
}

TEST_CASE("framing: a well-framed reply that does not answer the request is a bad reply, decided at once") {
    Sent s(write_tx(0, 2, 0x0601, 1));
    // FC06 echoing another value: right address, function and CRC, wrong content. The
    // device answered: the transaction ends now (0x04 northbound), not at the timeout.
    const Bytes wrong_echo = rtu(2, fp::encode_response(fp::WriteSingleResponse{0x06, 0x0601, 2}));
    s.master.on_bytes(wrong_echo, s.tx_end + 2ms);
    CHECK(s.master.counters().bad_replies == 1);
    CHECK(expect_finished(s.master, s.tx_end + 2ms).outcome.status == OutcomeStatus::bad_reply);
    CHECK(s.master.counters().timeouts == 0);

    // A read of one register (read_model) answered with two (framed by its own byte
    // count, good CRC): the same, as soon as its last byte is in.
    Sent read;
    const Bytes two = rtu(2, Bytes{0x03, 0x04, 0x00, 0x01, 0x00, 0x02});
    read.master.on_bytes(fp::ByteView(two).first(two.size() - 1), read.tx_end + 2ms);
    CHECK(std::holds_alternative<fe::line_action::Wait>(read.master.next_action(read.tx_end + 2ms)));
    read.master.on_bytes(fp::ByteView(two).last(1), read.tx_end + 2ms + 100us);
    CHECK(expect_finished(read.master, read.tx_end + 2ms + 100us).outcome.status == OutcomeStatus::bad_reply);
    CHECK(read.master.counters().bad_replies == 1);
}

TEST_CASE("framing: bytes after the reply, and a late reply, are garbage that pushes the silence") {
    Sent s;
    s.master.on_bytes(concat({read_model_reply, Bytes{0x00, 0x00}}), s.tx_end + 2ms);
    CHECK(expect_finished(s.master, s.tx_end + 2ms).outcome.status == OutcomeStatus::ok);
    CHECK(s.master.counters().garbage_bytes == 2);

    Sent late;
    CHECK(expect_finished(late.master, late.reply_deadline).outcome.status == OutcomeStatus::timeout);
    const TimePoint arrived = late.reply_deadline + 3ms;
    late.master.on_bytes(read_model_reply, arrived);  // the device answered after all
    CHECK(late.master.counters().garbage_bytes == read_model_reply.size());
    CHECK(late.master.counters().replies == 0);
    late.master.start(read_model(), arrived);
    CHECK(expect_wait(late.master, arrived) == arrived + late.master.timing().t3_5());
}

}  // namespace
