// A WTEC-485 in ASCII mode behind the uniform register view (spec §5; seed 003):
// writes become ASCII commands sent one after another, stopping at the first failure.
#include <doctest/doctest.h>

#include "agent_support.hpp"

namespace {

using namespace fbt;
using fe::Table;
using fp::ExceptionCode;

fw::DriverParams driver() { return fw::DriverParams{0x0007A120, 0x004C4B40, 200, 0, 0x03, 0x02, 0x2710, 0x10, 0}; }
fw::GripperParams gripper() { return fw::GripperParams{5000, 80, 0x80, 0x0A, 1}; }

/// Answers every open poll as a homed gripper at rest.
void answer_polls(FakeLine& line) {
    for (std::size_t i = 0; i < line.sent.size(); ++i) {
        if (line.sent[i].done || line.at(i).priority != fe::Priority::poll) continue;
        const fe::Transaction& t = line.at(i);
        const fw::Reply reply = std::visit(
            [](const auto& c) -> fw::Reply {
                using C = std::decay_t<decltype(c)>;
                if constexpr (std::is_same_v<C, fw::ReadRunning>) return fw::RunningValues{4800, 3, true, 0x01};
                if constexpr (std::is_same_v<C, fw::QueryHoming>) return fw::StateCode{0x01};
                if constexpr (std::is_same_v<C, fw::ReadGripper>) return gripper();
                if constexpr (std::is_same_v<C, fw::ReadDriver>) return driver();
                if constexpr (std::is_same_v<C, fw::ReadHoming>)
                    return fw::HomingParams{0xFC, 0x7530, 0x30D40, 0x3E8, 0x41, 1, 0xC8, 0x989680};
                if constexpr (std::is_same_v<C, fw::ReadVersion>) return fw::Version{"Cstep [A]1.62"};
                if constexpr (std::is_same_v<C, fw::ReadPid>) return fw::Pid{1, 2, 3};
                if constexpr (std::is_same_v<C, fw::ReadRelease>) return fw::ReleaseParams{10, 20};
                FAIL("the view polls no such command");
                return fw::Ack{};
            },
            std::get<fe::AsciiPayload>(t.payload).command);
        line.reply(i, ascii_reply(t, reply));
    }
}

/// The commands (not polls, not reads) submitted so far, in order.
std::vector<std::size_t> commands(const FakeLine& line) {
    std::vector<std::size_t> out;
    for (std::size_t i = 0; i < line.sent.size(); ++i) {
        if (line.at(i).priority == fe::Priority::command) out.push_back(i);
    }
    return out;
}

/// A polled WTEC ASCII agent whose image holds R and N (force and speed need them).
struct Wtec : Rig {
    Wtec() : Rig(fe::DeviceType::wtec_ascii) {
        agent->start();
        await_sent(8);
        answer_polls(line);
        REQUIRE(agent->image().value(Table::input, 0x1010) == 200);  // R max current
    }
};

const fp::Request force_speed_position = fp::WriteMultipleRegistersRequest{0x0103, {50, 60, 70}};

}  // namespace

TEST_CASE("agent wtec ascii: the view's poll plan goes as ASCII commands") {
    Rig rig(fe::DeviceType::wtec_ascii);
    CHECK(rig.agent->poll_items() == 8);
    rig.agent->start();
    rig.await_sent(8);
    CHECK(rig.line.sent.size() == 8);
    CHECK(rig.line.count(ascii(fw::ReadRunning{})) == 1);
    CHECK(rig.line.count(ascii(fw::ReadVersion{})) == 1);
    answer_polls(rig.line);
    CHECK(rig.agent->image().value(Table::holding, 0x0202) == 1);  // grip state from I
    CHECK(rig.agent->image().value(Table::holding, 0x0200) == 1);  // init state from g
}

TEST_CASE("agent wtec ascii: a write becomes ASCII commands submitted one after another") {
    Wtec rig;
    rig.request(force_speed_position);
    auto sent = commands(rig.line);
    REQUIRE(sent.size() == 1);  // the next only after this one succeeded
    // 0x0103 force 50 % of R's max current 200 -> C 100.
    CHECK(same(rig.line.at(sent[0]).payload, ascii(fw::SetPeakCurrent{100})));
    CHECK(rig.line.at(sent[0]).delay_before == fe::Duration{4ms});
    CHECK_FALSE(rig.line.at(sent[0]).retry_allowed);
    CHECK(rig.line.at(sent[0]).deadline);
    run_for(rig.io, 20ms);
    CHECK(commands(rig.line).size() == 1);

    rig.line.reply(sent[0], ascii_reply(rig.line.at(sent[0]), fw::Ack{}));
    sent = commands(rig.line);
    REQUIRE(sent.size() == 2);
    // 0x0104 speed 60 % -> n with N as read and the new grip current (N max current), speed 153.
    fw::GripperParams n = gripper();
    n.max_current = 100;
    n.speed = 153;
    CHECK(same(rig.line.at(sent[1]).payload, ascii(fw::WriteGripper{n})));
    rig.line.reply(sent[1], ascii_reply(rig.line.at(sent[1]), fw::Ack{}));

    sent = commands(rig.line);
    REQUIRE(sent.size() == 3);
    // 0x0105 position 70 % of the stroke 10000 -> D 7000.
    CHECK(same(rig.line.at(sent[2]).payload, ascii(fw::SetTarget{7000})));
    rig.line.reply(sent[2], ascii_reply(rig.line.at(sent[2]), fw::Ack{}));

    rig.await_answers(1);
    CHECK(rig.last_answer() == fp::Response{fp::WriteMultipleResponse{fp::fc::write_multiple_registers, 0x0103, 3}});
    CHECK(rig.agent->image().value(Table::holding, 0x0104) == 60);
    CHECK(rig.agent->image().value(Table::holding, 0x0105) == 70);
}

TEST_CASE("agent wtec ascii: a sequence stops at the first payload that fails") {
    Wtec rig;
    rig.request(force_speed_position);
    auto sent = commands(rig.line);
    rig.line.reply(sent[0], ascii_reply(rig.line.at(sent[0]), fw::Ack{}));
    sent = commands(rig.line);
    REQUIRE(sent.size() == 2);
    rig.line.fail(sent[1], fe::OutcomeStatus::timeout);
    rig.await_answers(1);
    CHECK(rig.last_answer() == exception(fp::fc::write_multiple_registers, ExceptionCode::gateway_target_failed));
    run_for(rig.io, 30ms);
    CHECK(commands(rig.line).size() == 2);  // D never went
    CHECK(rig.line.count(ascii(fw::SetTarget{7000})) == 0);
}

TEST_CASE("agent wtec ascii: a reply that is not an acknowledgement stops the sequence too") {
    Wtec rig;
    rig.request(fp::WriteMultipleRegistersRequest{0x0104, {60, 70}});
    auto sent = commands(rig.line);
    REQUIRE(sent.size() == 1);
    rig.line.reply(sent[0], fe::Reply{fw::Reply{fw::StateCode{1}}});
    rig.await_answers(1);
    CHECK(rig.last_answer() == exception(fp::fc::write_multiple_registers, ExceptionCode::gateway_target_failed));
    CHECK(commands(rig.line).size() == 1);
}

TEST_CASE("agent wtec ascii: a D echoed back was not executed: 0x04 at once, with a notice, not 0x0B") {
    Wtec rig;
    rig.request(fp::WriteSingleRegisterRequest{0x0105, 30});
    const auto sent = commands(rig.line);
    REQUIRE(sent.size() == 1);
    CHECK(same(rig.line.at(sent[0]).payload, ascii(fw::SetTarget{3000})));
    rig.line.reply(sent[0], fe::Reply{fw::Reply{fw::NotExecuted{}}});
    rig.await_answers(1);
    CHECK(rig.last_answer() == exception(fp::fc::write_single_register, ExceptionCode::server_device_failure));
    CHECK(commands(rig.line).size() == 1);
    REQUIRE(rig.notices.size() == 1);  // logged and published with the reason
    CHECK(rig.notices[0].text.find("did not execute `D`") != std::string::npos);
}

TEST_CASE("agent wtec ascii: initialise sends a1 then G") {
    Wtec rig;
    rig.request(fp::WriteSingleRegisterRequest{0x0100, 1});
    auto sent = commands(rig.line);
    REQUIRE(sent.size() == 1);
    CHECK(same(rig.line.at(sent[0]).payload, ascii(fw::SetMotorEnable{true})));
    rig.line.reply(sent[0], ascii_reply(rig.line.at(sent[0]), fw::Ack{}));
    sent = commands(rig.line);
    REQUIRE(sent.size() == 2);
    CHECK(same(rig.line.at(sent[1]).payload, ascii(fw::Home{})));
    rig.line.reply(sent[1], ascii_reply(rig.line.at(sent[1]), fw::Ack{}));
    rig.await_answers(1);
    CHECK(rig.last_answer() == fp::Response{fp::WriteSingleResponse{fp::fc::write_single_register, 0x0100, 1}});
}

TEST_CASE("agent wtec ascii: stop() between payloads ends the sequence as cancelled, 0x0A") {
    Wtec rig;
    rig.request(force_speed_position);
    const auto sent = commands(rig.line);
    rig.agent->stop();
    rig.line.reply(sent[0], ascii_reply(rig.line.at(sent[0]), fw::Ack{}));
    rig.await_answers(1);
    CHECK(rig.last_answer() == exception(fp::fc::write_multiple_registers, ExceptionCode::gateway_path_unavailable));
    CHECK(commands(rig.line).size() == 1);
    CHECK(rig.agent->image().value(Table::input, 0x1008) == 100);  // the C reply still landed
}

TEST_CASE("agent wtec ascii: a read the image cannot answer sends the commands that fill it") {
    Wtec rig;  // max_age 0: always from the device
    rig.request(fp::ReadRegistersRequest{fp::fc::read_holding_registers, 0x0202, 1});
    const std::size_t d = rig.line.open(ascii(fw::QueryGripState{}));
    CHECK(rig.line.at(d).priority == fe::Priority::on_demand);
    rig.line.reply(d, ascii_reply(rig.line.at(d), fw::StateCode{0x02}));
    rig.await_answers(1);
    CHECK(rig.last_answer() == fp::Response{fp::ReadRegistersResponse{fp::fc::read_holding_registers, {2}}});
}
