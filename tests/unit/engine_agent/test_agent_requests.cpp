// Northbound requests through the device agent (spec §4), XEG profile (seed 001).
#include <doctest/doctest.h>

#include "xeg_support.hpp"

namespace {

using namespace fbt;
using fe::Table;
using fp::ExceptionCode;

}  // namespace

TEST_CASE("agent requests: what the profile refuses is answered locally, later, without line time") {
    Rig rig(fe::DeviceType::hiwin_xeg, quiet());
    rig.request(fp::ReadRegistersRequest{fp::fc::read_input_registers, 0x0300, 7});  // across the 0x0302 hole
    rig.request(fp::ReadBitsRequest{fp::fc::read_coils, 0, 8});                      // FC01: the XEG lacks it
    rig.request(fp::WriteSingleRegisterRequest{0x0630, 9000});                       // beyond any stroke
    CHECK(rig.answers.got.empty());  // never from inside request()
    rig.await_answers(3);
    CHECK(rig.answers.got[0] == exception(fp::fc::read_input_registers, ExceptionCode::illegal_data_address));
    CHECK(rig.answers.got[1] == exception(fp::fc::read_coils, ExceptionCode::illegal_function));
    CHECK(rig.answers.got[2] == exception(fp::fc::write_single_register, ExceptionCode::illegal_data_value));
    CHECK(rig.line.sent.empty());
}

TEST_CASE("agent requests: a read goes to the line when the image is not fresh, then comes from the image") {
    Rig rig(fe::DeviceType::hiwin_xeg, quiet(10s));
    const fe::TimePoint before = Clock::now();
    rig.request(fp::ReadRegistersRequest{fp::fc::read_holding_registers, 0x0640, 7});
    const fe::TimePoint after = Clock::now();
    REQUIRE(rig.line.sent.size() == 1);
    const fe::Transaction& t = rig.line.at(0);
    CHECK(same(t.payload, read_holding(0x0640, 7)));
    CHECK(t.priority == fe::Priority::on_demand);
    CHECK(t.retry_allowed);
    CHECK_FALSE(t.urgent);
    CHECK(t.delay_before == fe::Duration{});
    CHECK(t.device == 3);
    CHECK(t.address == 7);
    // A client never waits forever: reads carry the command deadline too.
    REQUIRE(t.deadline);
    CHECK(*t.deadline >= before + 300ms);
    CHECK(*t.deadline <= after + 300ms);
    rig.line.reply(0, pdu_reply(t, "03 0E 00 01 0F A0 07 D0 0F A0 07 D0 00 50 00 00"));
    rig.await_answers(1);
    CHECK(rig.last_answer() == fp::Response{fp::ReadRegistersResponse{
                                   fp::fc::read_holding_registers, {1, 4000, 2000, 4000, 2000, 80, 0}}});
    CHECK(rig.agent->image().value(Table::holding, 0x0645) == 80);

    // Fresh now: the same read and a part of it come from the image.
    rig.request(fp::ReadRegistersRequest{fp::fc::read_holding_registers, 0x0642, 3});
    rig.await_answers(2);
    CHECK(rig.last_answer() ==
          fp::Response{fp::ReadRegistersResponse{fp::fc::read_holding_registers, {2000, 4000, 2000}}});
    CHECK(rig.line.sent.size() == 1);
    // Registers never read go to the line.
    rig.request(fp::ReadRegistersRequest{fp::fc::read_holding_registers, 0x0640, 8});  // 0x0647 is a hole
    rig.await_answers(3);
    CHECK(rig.last_answer() == exception(fp::fc::read_holding_registers, ExceptionCode::illegal_data_address));
    rig.request(fp::ReadRegistersRequest{fp::fc::read_holding_registers, 0x0630, 3});
    CHECK(rig.line.sent.size() == 2);
}

TEST_CASE("agent requests: with max_age 0 every read goes to the line") {
    Rig rig(fe::DeviceType::hiwin_xeg, quiet(0ms));
    for (std::size_t k = 0; k < 2; ++k) {
        rig.request(fp::ReadBitsRequest{fp::fc::read_discrete_inputs, 0x0010, 8});
        REQUIRE(rig.line.sent.size() == k + 1);
        rig.line.reply(k, bits_reply(rig.line.at(k), {true, true, false, false, false, false, false, false}));
        rig.await_answers(k + 1);
    }
    CHECK(rig.last_answer() ==
          fp::Response{fp::ReadBitsResponse{fp::fc::read_discrete_inputs,
                                            {true, true, false, false, false, false, false, false}}});
}

TEST_CASE("agent requests: a write goes as a command with its deadline and the delay before command") {
    Rig rig(fe::DeviceType::hiwin_xeg, quiet(10s));
    const fe::TimePoint before = Clock::now();
    rig.request(fp::WriteMultipleRegistersRequest{0x0630, {3000, 5000, 1}});
    const fe::TimePoint after = Clock::now();
    REQUIRE(rig.line.sent.size() == 1);
    const fe::Transaction& t = rig.line.at(0);
    CHECK(same(t.payload, xeg::fc16(0x0630, {3000, 5000, 1})));
    CHECK(t.priority == fe::Priority::command);
    CHECK_FALSE(t.retry_allowed);  // rule 6
    CHECK_FALSE(t.urgent);
    CHECK(t.delay_before == fe::Duration{4ms});
    REQUIRE(t.deadline);
    CHECK(*t.deadline >= before + 300ms);
    CHECK(*t.deadline <= after + 300ms);
    CHECK_FALSE(t.poll_period);
    rig.line.reply(0, fc16_ack(t));
    rig.await_answers(1);
    CHECK(rig.last_answer() == fp::Response{fp::WriteMultipleResponse{fp::fc::write_multiple_registers, 0x0630, 3}});
    // The acknowledged values are in the image (the move flag auto-resets to 0).
    CHECK(rig.agent->image().value(Table::holding, 0x0630) == 3000);
    CHECK(rig.agent->image().value(Table::holding, 0x0632) == 0);
    // A write is never answered from the image, fresh or not.
    rig.request(fp::WriteMultipleRegistersRequest{0x0630, {3000, 5000, 1}});
    CHECK(rig.line.sent.size() == 2);
}

TEST_CASE("agent requests: an XEG FC06 goes out as FC16 and the client gets its FC06 echo") {
    Rig rig(fe::DeviceType::hiwin_xeg, quiet());
    rig.request(fp::WriteSingleRegisterRequest{0x0601, 5});
    REQUIRE(rig.line.sent.size() == 1);
    const fe::Transaction& t = rig.line.at(0);
    // Seed 001 §4.1: the controller knows FC16 only; one register.
    CHECK(fp::encode_request(request_of(t)) == bytes("10 06 01 00 01 02 00 05"));
    rig.line.reply(0, pdu_reply(t, "10 06 01 00 01"));
    rig.await_answers(1);
    CHECK(rig.last_answer() == fp::Response{fp::WriteSingleResponse{fp::fc::write_single_register, 0x0601, 5}});
}

TEST_CASE("agent requests: a stop is an urgent command; other writes are not") {
    Rig rig(fe::DeviceType::hiwin_xeg, quiet());
    rig.request(fp::WriteSingleRegisterRequest{0x0620, 1});
    rig.request(fp::WriteSingleRegisterRequest{0x0620, 0});
    REQUIRE(rig.line.sent.size() == 2);
    CHECK(rig.line.at(0).urgent);
    CHECK(rig.line.at(0).priority == fe::Priority::command);
    CHECK_FALSE(rig.line.at(1).urgent);
}

TEST_CASE("agent requests: device exceptions pass through under the client's function code") {
    Rig rig(fe::DeviceType::hiwin_xeg, quiet());
    rig.request(fp::WriteSingleRegisterRequest{0x0631, 5000});
    rig.line.reply(0, pdu_reply(rig.line.at(0), "90 03"));  // to the FC16 on the wire
    rig.request(fp::ReadRegistersRequest{fp::fc::read_input_registers, 0x0303, 4});
    rig.line.reply(1, pdu_reply(rig.line.at(1), "84 02"));
    rig.await_answers(2);
    CHECK(rig.answers.got[0] == exception(fp::fc::write_single_register, ExceptionCode::illegal_data_value));
    CHECK(rig.answers.got[1] == exception(fp::fc::read_input_registers, ExceptionCode::illegal_data_address));
}

TEST_CASE("agent requests: XEG exception 0x04 brings an FC07 read; its status is logged and reported") {
    Rig rig(fe::DeviceType::hiwin_xeg, quiet());
    rig.request(fp::WriteSingleRegisterRequest{0x0632, 1});  // move without a valid position
    rig.line.reply(0, pdu_reply(rig.line.at(0), "90 04"));
    rig.await_answers(1);
    CHECK(rig.last_answer() == exception(fp::fc::write_single_register, ExceptionCode::server_device_failure));
    // The follow-up: an on-demand FC07 (seed 001 §4.2.4).
    REQUIRE(rig.line.sent.size() == 2);
    CHECK(same(rig.line.at(1).payload, modbus(fp::ReadExceptionStatusRequest{})));
    CHECK(rig.line.at(1).priority == fe::Priority::on_demand);
    CHECK(rig.line.at(1).retry_allowed);
    // Another 0x04 while it is on its way asks for nothing more.
    rig.request(fp::WriteSingleRegisterRequest{0x0632, 1});
    rig.line.reply(2, pdu_reply(rig.line.at(2), "90 04"));
    CHECK(rig.line.sent.size() == 3);

    rig.line.reply(1, pdu_reply(rig.line.at(1), "07 07"));
    REQUIRE(rig.notices.size() == 1);
    CHECK(rig.notices[0].code == 0x07);
    CHECK(rig.notices[0].text.find("incorrect move") != std::string::npos);
    CHECK(rig.logs.count(fe::LogLevel::warning, "incorrect move") == 1);
    CHECK(rig.logs.count(fe::LogLevel::warning, "gripper1") >= 1);
}

TEST_CASE("agent requests: FC07 from a client goes to the line and its answer comes back") {
    Rig rig(fe::DeviceType::hiwin_xeg, quiet(10s));
    rig.request(fp::ReadExceptionStatusRequest{});
    REQUIRE(rig.line.sent.size() == 1);
    CHECK(rig.line.at(0).priority == fe::Priority::on_demand);
    rig.line.reply(0, pdu_reply(rig.line.at(0), "07 00"));
    rig.await_answers(1);
    CHECK(rig.last_answer() == fp::Response{fp::ReadExceptionStatusResponse{0}});
}

TEST_CASE("agent requests: after stop() nothing goes to the line; the client gets 0x0A") {
    Rig rig(fe::DeviceType::hiwin_xeg, quiet());
    rig.agent->stop();
    rig.request(fp::ReadRegistersRequest{fp::fc::read_input_registers, 0x0300, 2});
    rig.await_answers(1);
    CHECK(rig.last_answer() == exception(fp::fc::read_input_registers, ExceptionCode::gateway_path_unavailable));
    CHECK(rig.line.sent.empty());
}

TEST_CASE("agent requests: a line answer reaches the client from the line's completion, not a later loop pass") {
    // The line worker completes a transaction on the loop; the agent hands the answer
    // over right there, so a client that asks again is queued in the same pass
    // (docs/performance.md, "CPU per transaction").
    Rig rig(fe::DeviceType::hiwin_xeg, quiet(0ms));
    rig.request(fp::ReadRegistersRequest{fp::fc::read_input_registers, 0x0300, 2});
    REQUIRE(rig.line.sent.size() == 1);
    rig.line.reply(0, registers_reply(rig.line.at(0), {0, 1}));
    REQUIRE(rig.answers.got.size() == 1);  // no io.run() in between
    CHECK(rig.last_answer() == fp::Response{fp::ReadRegistersResponse{fp::fc::read_input_registers, {0, 1}}});
    // Failures too (0x0B for a read that timed out).
    rig.request(fp::ReadRegistersRequest{fp::fc::read_input_registers, 0x0300, 2});
    REQUIRE(rig.line.sent.size() == 2);
    rig.line.fail(1, fe::OutcomeStatus::timeout);
    REQUIRE(rig.answers.got.size() == 2);
    CHECK(rig.last_answer() ==
          exception(fp::fc::read_input_registers, ExceptionCode::gateway_target_failed));
}

TEST_CASE("agent requests: a line that completes inside request() still never answers from inside it") {
    Rig rig(fe::DeviceType::hiwin_xeg, quiet(0ms));
    rig.line.complete_inline = fe::OutcomeStatus::queue_full;
    rig.request(fp::ReadRegistersRequest{fp::fc::read_input_registers, 0x0300, 2});
    REQUIRE(rig.line.sent.size() == 1);
    CHECK(rig.answers.got.empty());
    rig.await_answers(1);
    CHECK(rig.last_answer() == exception(fp::fc::read_input_registers, ExceptionCode::server_device_busy));
}
