// The line may complete an agent's transactions after the agent is gone (it owns
// them once submitted). Run under ASan, these tests show the late completions touch
// nothing that was freed.
#include <doctest/doctest.h>

#include "xeg_support.hpp"

namespace {

using namespace fbt;
using fp::ExceptionCode;

}  // namespace

TEST_CASE("agent lifetime: destroyed with polls and requests outstanding; late completions are harmless") {
    Rig rig(fe::DeviceType::hiwin_xeg);
    rig.agent->start();
    rig.await_sent(5);
    rig.request(fp::ReadRegistersRequest{fp::fc::read_holding_registers, 0x0640, 7});
    rig.request(fp::WriteSingleRegisterRequest{0x0632, 1});
    REQUIRE(rig.line.sent.size() == 7);

    rig.agent.reset();
    // Unfinished requests are answered once, from the loop, as cancelled: 0x0A, like
    // a cancelled request of every other target (docs/modbus-tcp.md).
    CHECK(rig.answers.got.empty());
    rig.await_answers(2);
    CHECK(rig.answers.got[0] == exception(fp::fc::read_holding_registers, ExceptionCode::gateway_path_unavailable));
    CHECK(rig.answers.got[1] == exception(fp::fc::write_single_register, ExceptionCode::gateway_path_unavailable));

    // The line completes everything afterwards: replies, an exception that would
    // ask for a follow-up, a split, failures.
    xeg::answer_polls(rig.line);
    rig.line.reply(5, pdu_reply(rig.line.at(5), "03 0E 00 01 0F A0 07 D0 0F A0 07 D0 00 50 00 00"));
    rig.line.reply(6, pdu_reply(rig.line.at(6), "90 04"));
    CHECK(rig.line.open_count() == 0);
    // No timer of the agent fires, nothing more is submitted or answered.
    run_for(rig.io, 60ms);
    CHECK(rig.line.sent.size() == 7);
    CHECK(rig.answers.got.size() == 2);
}

TEST_CASE("agent lifetime: destroyed with a follow-up and a split pending") {
    Rig rig(fe::DeviceType::hiwin_xeg);
    rig.agent->start();
    rig.await_sent(5);
    // A poll answered 0x04 asks for FC07; the status block answered 0x02 is split.
    std::size_t i = rig.line.open(xeg::model());
    rig.line.reply(i, exception_reply(rig.line.at(i), ExceptionCode::server_device_failure));
    i = rig.line.open(xeg::status());
    rig.line.reply(i, exception_reply(rig.line.at(i), ExceptionCode::illegal_data_address));
    REQUIRE(rig.line.has_open(modbus(fp::ReadExceptionStatusRequest{})));
    REQUIRE(run_until(rig.io, [&] { return rig.line.has_open(read_input(0x0300, 1)); }));
    rig.agent.reset();
    for (std::size_t k = 0; k < rig.line.sent.size(); ++k) {
        if (!rig.line.sent[k].done) rig.line.fail(k, fe::OutcomeStatus::cancelled);
    }
    run_for(rig.io, 30ms);
    CHECK(rig.line.open_count() == 0);
}

TEST_CASE("agent lifetime: an agent destroyed by its own response handler") {
    Rig rig(fe::DeviceType::hiwin_xeg);
    rig.agent->start();
    rig.await_sent(5);
    bool answered = false;
    rig.agent->request(fp::ReadRegistersRequest{fp::fc::read_input_registers, 0x0300, 2},
                       [&](const fp::Response&) {
                           answered = true;
                           rig.agent.reset();
                       });
    const std::size_t read = rig.line.sent.size() - 1;
    rig.line.reply(read, registers_reply(rig.line.at(read), {1, 2}));
    REQUIRE(run_until(rig.io, [&] { return answered; }));
    CHECK_FALSE(rig.agent);
    xeg::answer_polls(rig.line);
    run_for(rig.io, 30ms);
}
