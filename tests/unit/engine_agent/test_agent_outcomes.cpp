// Transactions that end without a reply, as Modbus exceptions (spec §4, §3 rule 9).
#include <doctest/doctest.h>

#include "engine/device_agent_answers.hpp"
#include "xeg_support.hpp"

namespace {

using namespace fbt;
using fe::OutcomeStatus;
using fp::ExceptionCode;

struct Case {
    OutcomeStatus status;
    ExceptionCode code;
};

}  // namespace

TEST_CASE("agent outcomes: each failure maps to its exception, under the client's function code") {
    const Case cases[] = {
        {OutcomeStatus::timeout, ExceptionCode::gateway_target_failed},
        {OutcomeStatus::device_offline, ExceptionCode::gateway_target_failed},
        // Spec §4: "0x0A when ... its line is down"; nothing was sent.
        {OutcomeStatus::line_down, ExceptionCode::gateway_path_unavailable},
        // Spec §4 / rule 9: "0x0B when ... a command's deadline passed".
        {OutcomeStatus::expired, ExceptionCode::gateway_target_failed},
        {OutcomeStatus::queue_full, ExceptionCode::server_device_busy},
        // Shut down or reconfigured before it was sent: the path went away.
        {OutcomeStatus::cancelled, ExceptionCode::gateway_path_unavailable},
        {OutcomeStatus::invalid_request, ExceptionCode::server_device_failure},
    };
    for (const Case& c : cases) {
        CAPTURE(fe::to_string(c.status));
        CHECK(fe::exception_for(c.status) == c.code);
        Rig rig(fe::DeviceType::hiwin_xeg, quiet());
        rig.request(fp::ReadRegistersRequest{fp::fc::read_input_registers, 0x0300, 2});
        rig.request(fp::WriteSingleRegisterRequest{0x0631, 100});  // goes as FC16
        REQUIRE(rig.line.sent.size() == 2);
        rig.line.fail(0, c.status);
        rig.line.fail(1, c.status);
        rig.await_answers(2);
        CHECK(rig.answers.got[0] == exception(fp::fc::read_input_registers, c.code));
        CHECK(rig.answers.got[1] == exception(fp::fc::write_single_register, c.code));
    }
}

TEST_CASE("agent outcomes: a write that timed out leaves what it wrote stale") {
    Rig rig(fe::DeviceType::hiwin_xeg, quiet());
    rig.request(fp::WriteSingleRegisterRequest{0x0631, 100});
    rig.line.reply(0, fc16_ack(rig.line.at(0)));
    CHECK(rig.agent->image().quality(fe::Table::holding, 0x0631) == fe::Quality::good);
    rig.request(fp::WriteSingleRegisterRequest{0x0631, 200});
    rig.line.fail(1, OutcomeStatus::timeout);
    CHECK(rig.agent->image().quality(fe::Table::holding, 0x0631) == fe::Quality::stale);
    rig.await_answers(2);
}

TEST_CASE("agent outcomes: a line that completes inside submit() still answers later, once") {
    Rig rig(fe::DeviceType::hiwin_xeg, quiet());
    rig.line.complete_inline = OutcomeStatus::queue_full;
    rig.request(fp::WriteSingleRegisterRequest{0x0620, 1});
    CHECK(rig.answers.got.empty());
    rig.await_answers(1);
    CHECK(rig.last_answer() == exception(fp::fc::write_single_register, ExceptionCode::server_device_busy));
    run_for(rig.io, 20ms);
    CHECK(rig.answers.got.size() == 1);
}

TEST_CASE("agent outcomes: polls completed inside submit() are not resubmitted in a tight loop") {
    Rig rig(fe::DeviceType::hiwin_xeg);
    rig.line.complete_inline = OutcomeStatus::device_offline;
    rig.agent->start();
    rig.await_sent(5);
    run_for(rig.io, 50ms);
    // About 50 ms: the status item once per 20 ms period (a tight loop would make it
    // thousands), the others not again.
    CHECK(rig.line.count(xeg::status()) <= 6);
    CHECK(rig.line.count(xeg::di()) == 1);
    CHECK(rig.line.count(xeg::model()) == 1);
}
