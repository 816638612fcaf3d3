// UpstreamTarget against the real R6 simulator (fieldbridge-sim --r6): the manual's
// exchanges, counter reads of two clients interleaved, reconnect after the
// simulator dies, state polling.
#include <doctest/doctest.h>

#include <memory>
#include <string>
#include <utility>

#include "northbound/upstream/upstream_target.hpp"
#include "sim_process.hpp"
#include "upstream_test_support.hpp"

using namespace fieldbridge;
using namespace fieldbridge::northbound;
using namespace fieldbridge::northbound::upstream;
using namespace fbtest;
using fieldbridge::test::SimProcess;
using std::chrono::milliseconds;

namespace {

/// Seed 004 sections 3.1-3.3 as printed (MBAP header included), as in
/// tests/integration/sim/test_r6_tcp.py.
const std::vector<std::pair<const char*, const char*>> printed{
    {"00 00 00 00 00 06 01 03 00 00 00 01", "00 00 00 00 00 05 01 03 02 00 29"},
    {"00 00 00 00 00 06 01 03 00 82 00 01", "00 00 00 00 00 05 01 03 02 00 02"},
    {"00 00 00 00 00 06 01 03 00 83 00 04", "00 00 00 00 00 0b 01 03 08 00 00 00 00 00 00 00 01"},
    {"00 00 00 00 00 0B 01 10 08 83 00 02 04 00 00 00 01", "00 00 00 00 00 06 01 10 08 83 00 02"},
    {"00 00 00 00 00 06 01 03 08 83 00 06",
     "00 00 00 00 00 0f 01 03 0c 00 00 00 01 00 00 00 0a 00 00 00 05"},
    {"00 00 00 00 00 06 01 03 08 89 00 01", "00 00 00 00 00 05 01 03 02 00 03"},
    {"00 00 00 00 00 06 01 03 08 8a 00 01", "00 00 00 00 00 05 01 03 02 00 01"},
    {"00 00 00 00 00 06 01 03 08 8b 00 02", "00 00 00 00 00 07 01 03 04 00 00 00 00"},
    {"00 00 00 00 00 06 01 03 08 b3 00 02", "00 00 00 00 00 07 01 03 04 00 00 00 00"},
    {"00 00 00 00 00 06 01 03 08 db 00 01", "00 00 00 00 00 05 01 03 02 00 06"},
    {"00 00 00 00 00 06 01 03 08 dc 00 02", "00 00 00 00 00 07 01 03 04 00 00 00 00"},
    {"00 00 00 00 00 06 01 03 09 1c 00 02", "00 00 00 00 00 07 01 03 04 00 00 00 00"},
    {"00 00 00 00 00 06 01 03 09 5d 00 04", "00 00 00 00 00 0b 01 03 08 00 00 00 00 00 00 00 00"},
    {"00 00 00 00 00 06 01 03 09 61 00 04", "00 00 00 00 00 0b 01 03 08 00 00 00 00 00 00 00 00"},
    {"00 00 00 00 00 06 01 03 09 65 00 01", "00 00 00 00 00 05 01 03 02 00 01"},
    {"00 00 00 00 00 06 01 03 09 66 00 01", "00 00 00 00 00 05 01 03 02 00 00"},
    {"00 00 00 00 00 06 01 03 09 86 00 01", "00 00 00 00 00 05 01 03 02 00 00"},
    {"00 00 00 00 00 06 01 06 4e 20 00 01", "00 00 00 00 00 06 01 06 4e 20 00 01"},
    {"00 00 00 00 00 06 01 06 4e e8 00 64", "00 00 00 00 00 06 01 06 4e e8 00 64"},
    {"00 00 00 00 00 0B 01 10 08 b3 00 02 04 00 00 00 01", "00 00 00 00 00 06 01 10 08 b3 00 02"},
    {"00 00 00 00 00 13 01 10 4e 52 00 06 0c 00 00 00 01 00 00 00 00 00 00 00 08",
     "00 00 00 00 00 06 01 10 4e 52 00 06"},
    {"00 00 00 00 00 0d 01 10 4e 58 00 03 06 00 00 00 01 00 01", "00 00 00 00 00 06 01 10 4e 58 00 03"},
    {"00 00 00 00 00 0b 01 10 4f 4c 00 02 04 00 00 00 64", "00 00 00 00 00 06 01 10 4f 4c 00 02"},
};

/// The PDU of a printed frame (the MBAP header is the server's business).
Bytes pdu_of(const char* frame) {
    const Bytes all = hex(frame);
    return Bytes(all.begin() + 7, all.end());
}

/// One request through the target, answered within the bound.
Bytes ask(asio::io_context& io, UpstreamTarget& target, const Bytes& pdu, std::uint64_t who = 1) {
    auto answer = std::make_shared<Answer>();
    target.handle(core::UnitId{10}, pdu, client(who), capture(answer));
    REQUIRE_MESSAGE(run_until(io, [&] { return answer->done; }, milliseconds{5000}), "no answer to " << to_hex(pdu));
    return answer->pdu;
}

struct Running {
    asio::io_context io;
    std::uint16_t port = free_port();
    SimProcess sim{{"--r6", "127.0.0.1:" + std::to_string(port)}};
    CapturedLog log;
    std::unique_ptr<UpstreamTarget> target;

    explicit Running(UpstreamTuning tuning = {}) {
        target = std::make_unique<UpstreamTarget>(io, config_for(port), log.sink(), tuning);
        target->start();
        REQUIRE(run_until(io, [&] { return target->link_state() == LinkState::up; }));
    }
};

}  // namespace

TEST_CASE("every example exchange of the R6 manual comes back as printed") {
    Running r;
    for (const auto& [request, response] : printed) {
        CHECK_MESSAGE(to_hex(ask(r.io, *r.target, pdu_of(request))) == to_hex(pdu_of(response)), request);
    }
    // 3.1.10 needs alarm 805, 3.1.15 a moving robot.
    REQUIRE(r.sim.control("r6 alarm 805") == "ok");
    CHECK(ask(r.io, *r.target, pdu_of("00 00 00 00 00 06 01 03 09 5c 00 01")) ==
          pdu_of("00 00 00 00 00 05 01 03 02 03 25"));
    REQUIRE(r.sim.control("r6 clear") == "ok");
    REQUIRE(r.sim.control("r6 start") == "ok");
    CHECK(ask(r.io, *r.target, pdu_of("00 00 00 00 00 06 01 03 09 a6 00 01")) ==
          pdu_of("00 00 00 00 00 05 01 03 02 00 01"));
    // Device exceptions pass through unchanged: half an axis (02), unknown function (01).
    CHECK(ask(r.io, *r.target, hex("03 08 dd 00 01")) == hex("83 02"));
    CHECK(ask(r.io, *r.target, hex("2b")) == hex("ab 01"));
}

TEST_CASE("two clients reading counters concurrently each get their own counter") {
    Running r;
    const Bytes select0 = hex("10 08 83 00 02 04 00 00 00 00");
    const Bytes select1 = hex("10 08 83 00 02 04 00 00 00 01");
    const Bytes read = hex("03 08 83 00 06");
    for (int round = 0; round < 60; ++round) {
        // Interleaved as two PLCs would send them; without the sequence rule the two
        // selects (commands) would both go before the reads and one client would
        // read the other's counter.
        auto a_sel = std::make_shared<Answer>();
        auto b_sel = std::make_shared<Answer>();
        auto a_read = std::make_shared<Answer>();
        auto b_read = std::make_shared<Answer>();
        const bool a_first = round % 2 == 0;
        if (a_first) {
            r.target->handle(core::UnitId{10}, select0, client(1), capture(a_sel));
            r.target->handle(core::UnitId{10}, select1, client(2), capture(b_sel));
        } else {
            r.target->handle(core::UnitId{10}, select1, client(2), capture(b_sel));
            r.target->handle(core::UnitId{10}, select0, client(1), capture(a_sel));
        }
        r.target->handle(core::UnitId{10}, read, client(1), capture(a_read));
        if (round % 3 == 0) r.io.poll();  // sometimes let the first exchanges run in between
        r.target->handle(core::UnitId{10}, read, client(2), capture(b_read));
        REQUIRE(run_until(r.io, [&] { return a_read->done && b_read->done; }, milliseconds{5000}));
        CHECK(a_sel->pdu == hex("10 08 83 00 02"));
        CHECK(b_sel->pdu == hex("10 08 83 00 02"));
        REQUIRE(a_read->pdu.size() == 14);  // FC, byte count, 12 data bytes
        REQUIRE(b_read->pdu.size() == 14);
        // Bytes 2-5: the ID of the counter read.
        CHECK(to_hex(Bytes(a_read->pdu.begin() + 2, a_read->pdu.begin() + 6)) == "00 00 00 00");
        CHECK(to_hex(Bytes(b_read->pdu.begin() + 2, b_read->pdu.begin() + 6)) == "00 00 00 01");
    }
}

TEST_CASE("the simulator dies and comes back: 0x0A / 0x0B meanwhile, then it works again") {
    Running r;
    CHECK(ask(r.io, *r.target, hex("03 08 db 00 01")) == hex("03 02 00 06"));
    r.sim.terminate();
    // Whatever was out when it died is 0x0B, what arrives while it is down is 0x0A.
    const Bytes during = ask(r.io, *r.target, hex("03 08 db 00 01"));
    CHECK((during == hex("83 0A") || during == hex("83 0B")));
    REQUIRE(run_until(r.io, [&] { return r.target->link_state() != LinkState::up; }));
    CHECK(ask(r.io, *r.target, hex("03 08 db 00 01")) == hex("83 0A"));
    REQUIRE(r.target->state(core::UnitId{10}));
    CHECK_FALSE(r.target->state(core::UnitId{10})->online);
    r.sim.start();
    REQUIRE(run_until(r.io, [&] { return r.target->link_state() == LinkState::up; }, milliseconds{5000}));
    CHECK(ask(r.io, *r.target, hex("03 08 db 00 01")) == hex("03 02 00 06"));
    CHECK(r.target->stats().connects == 2);
    REQUIRE(run_until(r.io, [&] { return r.target->state(core::UnitId{10})->online; }));
}

TEST_CASE("state polling decodes mode, alarm, motion, axes, world and cycle times") {
    Running r;
    std::vector<R6State> reports;
    r.target->set_state_callback([&reports](const R6State& s) { reports.push_back(s); });
    const auto field = [&](const char* name) -> std::optional<engine::Field> {
        const auto s = r.target->state(core::UnitId{10});
        if (!s) return std::nullopt;
        const engine::Field* f = s->state.find(name);
        if (f == nullptr) return std::nullopt;
        return *f;
    };
    const auto int_of = [&](const char* name) -> std::optional<std::int64_t> {
        const auto f = field(name);
        if (!f || !std::holds_alternative<std::int64_t>(f->value)) return std::nullopt;
        return std::get<std::int64_t>(f->value);
    };
    REQUIRE(run_until(r.io, [&] { return r.target->state(core::UnitId{10})->online && int_of("axis_count"); }));
    CHECK(int_of("mode") == 3);
    CHECK(int_of("alarm") == 0);
    CHECK(int_of("axis_count") == 6);
    CHECK(int_of("cycle_time") == 0);
    CHECK(r.target->state(core::UnitId{10})->name == "robot");
    REQUIRE(field("axes_deg"));
    CHECK(std::get<std::vector<double>>(field("axes_deg")->value).size() == 6);
    REQUIRE(field("world_mm"));
    CHECK(std::get<std::vector<double>>(field("world_mm")->value).size() == 8);

    REQUIRE(r.sim.control("r6 alarm 805") == "ok");
    REQUIRE(run_until(r.io, [&] { return int_of("alarm") == 805; }));
    REQUIRE_FALSE(reports.empty());  // the change was reported
    CHECK(reports.back().online);
    CHECK(reports.back().alarms.size() == 1);
    REQUIRE(r.target->state(core::UnitId{10})->alarms.size() == 1);
    CHECK(r.target->state(core::UnitId{10})->alarms[0].code == "r6_alarm_805");
    REQUIRE(r.sim.control("r6 clear") == "ok");
    // Started through the pass-through (start button 0x4E23), as a PLC would.
    CHECK(ask(r.io, *r.target, hex("06 4e 23 00 01")) == hex("06 4e 23 00 01"));
    REQUIRE(run_until(r.io, [&] {
        const auto moving = field("moving");
        const auto axes = field("axes_deg");
        return moving && std::get<bool>(moving->value) && axes &&
               std::get<std::vector<double>>(axes->value).at(0) > 0.0 &&
               int_of("cycle_time").value_or(0) > 0;
    }));
    CHECK(int_of("mode") == 2);
    CHECK(r.target->state(core::UnitId{10})->alarms.empty());
    const auto image = r.target->image(core::UnitId{10});
    REQUIRE(image != nullptr);
    CHECK(image->quality(engine::Table::holding, 0x09A6) == engine::Quality::good);
    const std::size_t before = reports.size();
    r.sim.terminate();
    REQUIRE(run_until(r.io, [&] { return !r.target->state(core::UnitId{10})->online; }));
    CHECK(reports.size() > before);
    CHECK_FALSE(reports.back().online);
    CHECK(image->quality(engine::Table::holding, 0x09A6) == engine::Quality::offline);
}
