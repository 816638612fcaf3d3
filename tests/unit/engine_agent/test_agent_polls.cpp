// The device agent's polls (spec §3 rules 3, 6, 8; §5 XEG poll plan) on a real
// io_context with a fake line.
#include <doctest/doctest.h>

#include "xeg_support.hpp"

namespace {

using namespace fbt;
using fe::Table;

}  // namespace

TEST_CASE("agent polls: the whole XEG plan goes at start, together, as retried polls, and fills the image") {
    Rig rig(fe::DeviceType::hiwin_xeg);
    CHECK(rig.agent->poll_items() == 5);
    rig.agent->start();
    CHECK(rig.line.sent.empty());  // from the loop, not from inside start()
    rig.await_sent(1);
    // Due together, submitted together: all five in one go.
    REQUIRE(rig.line.sent.size() == 5);
    for (const auto& s : rig.line.sent) {
        const fe::Transaction& t = s.transaction;
        CHECK(t.priority == fe::Priority::poll);
        CHECK(t.retry_allowed);
        CHECK(t.device == 3);
        CHECK(t.address == 7);
        CHECK_FALSE(t.urgent);
        CHECK_FALSE(t.deadline);
    }
    CHECK(rig.line.at(rig.line.open(xeg::status())).poll_period == fe::Duration{20ms});
    CHECK(rig.line.at(rig.line.open(xeg::di())).poll_period == fe::Duration{400ms});
    CHECK(rig.line.at(rig.line.open(xeg::dout())).poll_period == fe::Duration{400ms});
    // Startup items have no period: the line ages them by its default.
    CHECK_FALSE(rig.line.at(rig.line.open(xeg::model())).poll_period);
    CHECK_FALSE(rig.line.at(rig.line.open(xeg::firmware())).poll_period);

    xeg::answer_polls(rig.line, 1234, xeg::positioned);
    const fe::RegisterImage& image = rig.agent->image();
    CHECK(image.value(Table::input, 0x0300) == 1234);
    CHECK(image.value(Table::input, 0x0301) == xeg::positioned);
    CHECK(image.quality(Table::input, 0x0301) == fe::Quality::good);
    CHECK(image.value(Table::holding, 0x0600) == xeg::xeg_32);
    CHECK(image.value(Table::input, 0x0306) == 884);
    CHECK(image.value(Table::discrete_inputs, 0x0006) == 1);
    CHECK(image.value(Table::discrete_inputs, 0x0010) == 1);
    CHECK(image.value(Table::discrete_inputs, 0x0011) == 0);
}

TEST_CASE("agent polls: each item again at its period; startup items once") {
    Rig rig(fe::DeviceType::hiwin_xeg);
    const fe::TimePoint started = Clock::now();
    rig.agent->start();
    rig.await_sent(5);
    xeg::answer_polls(rig.line);
    // Keep answering the status poll until it went four times.
    REQUIRE(run_until(rig.io, [&] {
        if (rig.line.has_open(xeg::status())) xeg::answer_polls(rig.line);
        return rig.line.count(xeg::status()) >= 4;
    }));
    const auto status = rig.line.all_of(xeg::status());
    for (std::size_t k = 0; k < status.size(); ++k) {
        // Timers never fire early: the k-th poll is at least k periods after start.
        CHECK(rig.line.sent[status[k]].at - started >= static_cast<int>(k) * 20ms);
    }
    REQUIRE(run_until(rig.io, [&] {
        xeg::answer_polls(rig.line);
        return rig.line.count(xeg::di()) >= 2;
    }));
    CHECK(rig.line.sent[rig.line.all_of(xeg::di())[1]].at - started >= 400ms);
    CHECK(rig.line.count(xeg::model()) == 1);
    CHECK(rig.line.count(xeg::firmware()) == 1);
}

TEST_CASE("agent polls: never a second poll of an item while one is on its way") {
    Rig rig(fe::DeviceType::hiwin_xeg);
    rig.agent->start();
    rig.await_sent(5);
    // Six fast periods pass with nothing answered: nothing more is submitted.
    run_for(rig.io, 120ms);
    CHECK(rig.line.sent.size() == 5);
    // Answered late, the status item is overdue and goes again at once; nothing else.
    const std::size_t first = rig.line.open(xeg::status());
    rig.line.reply(first, registers_reply(rig.line.at(first), {10, 0}));
    rig.await_sent(6);
    CHECK(same(rig.line.at(5).payload, xeg::status()));
    run_for(rig.io, 60ms);
    CHECK(rig.line.sent.size() == 6);
}

TEST_CASE("agent polls: a poll that times out leaves its registers stale, and reads go to the line") {
    fe::DeviceAgentConfig config = test_config();
    config.max_age = 10s;
    Rig rig(fe::DeviceType::hiwin_xeg, config);
    rig.agent->start();
    rig.await_sent(5);
    xeg::answer_polls(rig.line, 500, xeg::positioned);
    // Fresh: a client read of the status is answered from the image.
    rig.request(fp::ReadRegistersRequest{fp::fc::read_input_registers, 0x0300, 2});
    rig.await_answers(1);
    CHECK(rig.last_answer() == fp::Response{fp::ReadRegistersResponse{fp::fc::read_input_registers, {500, 2}}});

    REQUIRE(run_until(rig.io, [&] { return rig.line.has_open(xeg::status()); }));
    rig.line.fail(rig.line.open(xeg::status()), fe::OutcomeStatus::timeout);
    CHECK(rig.agent->image().quality(Table::input, 0x0300) == fe::Quality::stale);
    CHECK(rig.agent->image().value(Table::input, 0x0300) == 500);  // the value is kept

    const std::size_t before = rig.line.sent.size();
    rig.request(fp::ReadRegistersRequest{fp::fc::read_input_registers, 0x0300, 2});
    rig.await_sent(before + 1);
    const std::size_t read = rig.line.sent.size() - 1;
    CHECK(rig.line.at(read).priority == fe::Priority::on_demand);
    rig.line.reply(read, registers_reply(rig.line.at(read), {600, 2}));
    rig.await_answers(2);
    CHECK(rig.last_answer() == fp::Response{fp::ReadRegistersResponse{fp::fc::read_input_registers, {600, 2}}});
}

TEST_CASE("agent polls: a block answered 0x02 is split, remembered, and logged once per split") {
    Rig rig(fe::DeviceType::hiwin_xeg);
    rig.agent->start();
    rig.await_sent(5);
    const std::size_t block = rig.line.open(xeg::di());
    rig.line.reply(block, exception_reply(rig.line.at(block), fp::ExceptionCode::illegal_data_address));
    CHECK(rig.agent->poll_items() == 6);
    CHECK(rig.logs.count(fe::LogLevel::warning, "exception 0x02") == 1);
    // The halves go at once.
    REQUIRE(run_until(rig.io, [&] {
        return rig.line.has_open(read_discrete(0x0000, 4)) && rig.line.has_open(read_discrete(0x0004, 4));
    }));
    const std::size_t low = rig.line.open(read_discrete(0x0000, 4));
    rig.line.reply(low, bits_reply(rig.line.at(low), {true, true, false, true}));
    CHECK(rig.agent->image().value(Table::discrete_inputs, 0x0003) == 1);
    // A half rejected again is split again: a new event, a new log line.
    const std::size_t high = rig.line.open(read_discrete(0x0004, 4));
    rig.line.reply(high, exception_reply(rig.line.at(high), fp::ExceptionCode::illegal_data_address));
    CHECK(rig.agent->poll_items() == 7);
    CHECK(rig.logs.count(fe::LogLevel::warning, "exception 0x02") == 2);
    // The plan remembers: a slow period later the halves go, never the whole block.
    REQUIRE(run_until(rig.io, [&] {
        xeg::answer_polls(rig.line);
        for (std::size_t i = 0; i < rig.line.sent.size(); ++i) {
            const auto& p = rig.line.at(i).payload;
            if (!rig.line.sent[i].done && (same(p, read_discrete(0x0004, 2)) || same(p, read_discrete(0x0006, 2)))) {
                rig.line.reply(i, bits_reply(rig.line.at(i), {false, false}));
            }
        }
        return rig.line.count(read_discrete(0x0000, 4)) >= 2;
    }));
    CHECK(rig.line.count(xeg::di()) == 1);
    CHECK(rig.line.count(read_discrete(0x0004, 4)) == 1);
    CHECK(rig.logs.count(fe::LogLevel::warning, "exception 0x02") == 2);
}

TEST_CASE("agent polls: a single register refused alone is dropped from the plan") {
    Rig rig(fe::DeviceType::hiwin_xeg);
    rig.agent->start();
    rig.await_sent(5);
    std::size_t i = rig.line.open(xeg::status());
    rig.line.reply(i, exception_reply(rig.line.at(i), fp::ExceptionCode::illegal_data_address));
    REQUIRE(run_until(rig.io, [&] { return rig.line.has_open(read_input(0x0301, 1)); }));
    i = rig.line.open(read_input(0x0301, 1));
    rig.line.reply(i, exception_reply(rig.line.at(i), fp::ExceptionCode::illegal_data_address));
    CHECK(rig.agent->poll_items() == 5);  // 0x0300 alone and 0x0301 dropped
    CHECK(rig.logs.count(fe::LogLevel::warning, "not polled any more") == 1);
}

TEST_CASE("agent polls: other device exceptions are logged once, the item goes on") {
    Rig rig(fe::DeviceType::hiwin_xeg);
    rig.agent->start();
    rig.await_sent(5);
    for (int k = 0; k < 3; ++k) {
        REQUIRE(run_until(rig.io, [&] { return rig.line.has_open(xeg::status()); }));
        const std::size_t i = rig.line.open(xeg::status());
        rig.line.reply(i, exception_reply(rig.line.at(i), fp::ExceptionCode::server_device_busy));
    }
    CHECK(rig.logs.count(fe::LogLevel::warning, "exception 0x06") == 1);
    CHECK(rig.agent->poll_items() == 5);
}

TEST_CASE("agent polls: polling = false submits nothing; stop() ends polling") {
    fe::DeviceAgentConfig config = test_config();
    config.polling = false;
    Rig quiet(fe::DeviceType::hiwin_xeg, config);
    quiet.agent->start();
    run_for(quiet.io, 60ms);
    CHECK(quiet.line.sent.empty());

    Rig rig(fe::DeviceType::hiwin_xeg);
    rig.agent->start();
    rig.await_sent(5);
    rig.agent->stop();
    xeg::answer_polls(rig.line, 42);
    CHECK(rig.agent->image().value(Table::input, 0x0300) == 42);  // replies still land
    run_for(rig.io, 60ms);
    CHECK(rig.line.sent.size() == 5);
    rig.agent->start();  // a stopped agent stays stopped
    run_for(rig.io, 30ms);
    CHECK(rig.line.sent.size() == 5);
}
