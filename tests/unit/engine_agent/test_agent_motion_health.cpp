// The device agent's motion polling (spec §3 rule 5) and health (rules 7, 10).
#include <doctest/doctest.h>

#include "xeg_support.hpp"

namespace {

using namespace fbt;
using fe::Table;

/// Runs until the status item is on its way and returns its submission.
std::size_t next_status_poll(Rig& rig) {
    REQUIRE(run_until(rig.io, [&] { return rig.line.has_open(xeg::status()); }));
    return rig.line.open(xeg::status());
}

}  // namespace

TEST_CASE("agent motion: a motion command polls status at the motion period until the device is at rest") {
    Rig rig(fe::DeviceType::hiwin_xeg);
    rig.agent->start();
    rig.await_sent(5);
    xeg::answer_polls(rig.line, 1000, xeg::positioned);
    CHECK_FALSE(rig.agent->motion_polling());

    rig.request(fp::WriteSingleRegisterRequest{0x0601, 1});  // trigger a stored move
    CHECK(rig.agent->motion_polling());  // at once
    const std::size_t command = rig.line.open(xeg::fc16(0x0601, {1}));
    CHECK(rig.line.at(command).priority == fe::Priority::command);

    // The status item goes at the motion period from now on.
    std::size_t poll = next_status_poll(rig);
    CHECK(rig.line.at(poll).poll_period == fe::Duration{5ms});
    // A status from before the command finished does not end motion polling.
    rig.line.reply(poll, registers_reply(rig.line.at(poll), {1000, xeg::positioned}));
    CHECK(rig.agent->motion_polling());
    rig.line.reply(command, fc16_ack(rig.line.at(command)));
    rig.await_answers(1);
    CHECK(rig.last_answer() == fp::Response{fp::WriteSingleResponse{fp::fc::write_single_register, 0x0601, 1}});
    // The status polled before the command took effect is no longer served as fresh.
    CHECK(rig.agent->image().quality(Table::input, 0x0301) == fe::Quality::stale);

    // Moving: still at the motion period.
    poll = next_status_poll(rig);
    CHECK(rig.line.at(poll).poll_period == fe::Duration{5ms});
    rig.line.reply(poll, registers_reply(rig.line.at(poll), {1500, xeg::working}));
    CHECK(rig.agent->motion_polling());
    poll = next_status_poll(rig);
    CHECK(rig.line.at(poll).poll_period == fe::Duration{5ms});
    // At rest: back to the fast period.
    rig.line.reply(poll, registers_reply(rig.line.at(poll), {2000, xeg::positioned}));
    CHECK_FALSE(rig.agent->motion_polling());
    poll = next_status_poll(rig);
    CHECK(rig.line.at(poll).poll_period == fe::Duration{20ms});
    // Only the motion-flagged item changed period.
    for (const std::size_t i : rig.line.all_of(xeg::di())) {
        CHECK(rig.line.at(i).poll_period == fe::Duration{400ms});
    }
}

TEST_CASE("agent motion: a device seen moving is polled at the motion period without a command") {
    Rig rig(fe::DeviceType::hiwin_xeg);
    rig.agent->start();
    rig.await_sent(5);
    xeg::answer_polls(rig.line, 1000, xeg::working);  // someone pressed START
    CHECK(rig.agent->motion_polling());
    std::size_t poll = next_status_poll(rig);
    CHECK(rig.line.at(poll).poll_period == fe::Duration{5ms});
    rig.line.reply(poll, registers_reply(rig.line.at(poll), {1200, xeg::positioned}));
    CHECK_FALSE(rig.agent->motion_polling());
}

TEST_CASE("agent motion: a motion command that fails still ends in normal polling") {
    Rig rig(fe::DeviceType::hiwin_xeg);
    rig.agent->start();
    rig.await_sent(5);
    xeg::answer_polls(rig.line);
    rig.request(fp::WriteSingleRegisterRequest{0x0610, 1});  // reset: a motion command
    CHECK(rig.agent->motion_polling());
    rig.line.fail(rig.line.open(xeg::fc16(0x0610, {1})), fe::OutcomeStatus::expired);
    rig.await_answers(1);
    const std::size_t poll = next_status_poll(rig);
    rig.line.reply(poll, registers_reply(rig.line.at(poll), {1000, xeg::positioned}));
    CHECK_FALSE(rig.agent->motion_polling());
}

TEST_CASE("agent health: offline marks the image offline; back online it is stale and read again") {
    Rig rig(fe::DeviceType::hiwin_xeg);
    rig.agent->start();
    rig.await_sent(5);
    xeg::answer_polls(rig.line, 1000, xeg::working);
    CHECK(rig.agent->online());
    CHECK(rig.agent->motion_polling());

    rig.agent->on_health(false, Clock::now());
    CHECK_FALSE(rig.agent->online());
    CHECK(rig.agent->image().offline());
    CHECK(rig.agent->image().quality(Table::input, 0x0300) == fe::Quality::offline);
    CHECK(rig.agent->image().quality(Table::holding, 0x0600) == fe::Quality::offline);
    CHECK_FALSE(rig.agent->motion_polling());

    rig.agent->on_health(true, Clock::now());
    CHECK(rig.agent->online());
    CHECK_FALSE(rig.agent->image().offline());
    CHECK(rig.agent->image().quality(Table::input, 0x0300) == fe::Quality::stale);
    // Back: every item at once, the startup items (model, firmware) included.
    REQUIRE(run_until(rig.io, [&] {
        return rig.line.count(xeg::model()) == 2 && rig.line.count(xeg::firmware()) == 2 &&
               rig.line.count(xeg::di()) >= 2;
    }));
    xeg::answer_polls(rig.line, 1100, xeg::positioned);
    CHECK(rig.agent->image().quality(Table::input, 0x0300) == fe::Quality::good);
    CHECK(rig.agent->image().quality(Table::holding, 0x0600) == fe::Quality::good);
}

TEST_CASE("agent health: a startup item that failed is tried again later") {
    fe::DeviceAgentConfig config = test_config();
    config.startup_retry = 30ms;
    Rig rig(fe::DeviceType::hiwin_xeg, config);
    rig.agent->start();
    rig.await_sent(5);
    rig.line.fail(rig.line.open(xeg::model()), fe::OutcomeStatus::timeout);
    REQUIRE(run_until(rig.io, [&] { return rig.line.has_open(xeg::model()); }));
    const std::size_t again = rig.line.open(xeg::model());
    rig.line.reply(again, registers_reply(rig.line.at(again), {xeg::xeg_32}));
    run_for(rig.io, 100ms);
    CHECK(rig.line.count(xeg::model()) == 2);
}
