// UpstreamTarget against in-process scripted upstreams: timeouts, TTL, txid
// remapping with pipelined requests, local answers, teardown with requests out.
#include <doctest/doctest.h>

#include <algorithm>
#include <memory>

#include "northbound/upstream/upstream_target.hpp"
#include "upstream_test_support.hpp"

using namespace fieldbridge;
using namespace fieldbridge::northbound;
using namespace fieldbridge::northbound::upstream;
using namespace fbtest;
using std::chrono::milliseconds;


TEST_CASE("no reply within response_timeout: 0x0B; an expired command is never sent") {
    asio::io_context io;
    FakeUpstream silent(io, [](FakeUpstream&, const FakeUpstream::Request&) {});
    auto cfg = config_for(silent.port());
    cfg.poll_period = std::chrono::hours{1};  // only the first cycle's first read
    cfg.command_ttl = milliseconds{100};
    CapturedLog log;
    UpstreamTarget target(io, cfg, log.sink());
    target.start();
    REQUIRE(run_until(io, [&] { return target.link_state() == LinkState::up; }));
    auto read = std::make_shared<Answer>();
    target.handle(core::UnitId{10}, mode_read, client(1), capture(read));
    auto command = std::make_shared<Answer>();
    target.handle(core::UnitId{10}, hex("06 4E E8 00 64"), client(2), capture(command));
    CHECK_FALSE(read->done);  // never answered from inside handle()
    REQUIRE(run_until(io, [&] { return read->done && command->done; }, milliseconds{5000}));
    // The command waited behind the poll / read window past its 100 ms TTL.
    CHECK(command->pdu == hex("86 0B"));
    CHECK(read->pdu == hex("83 0B"));
    for (const auto& r : silent.requests()) CHECK(r.pdu[0] != 0x06);
    CHECK(log.contains("command_ttl"));
    CHECK(target.stats().expired == 1);
    CHECK(read->calls == 1);
    CHECK(command->calls == 1);
}

TEST_CASE("pipelined requests get their own answers: upstream transaction IDs remapped") {
    asio::io_context io;
    std::vector<FakeUpstream::Request> held;
    // Holds three requests, then answers them in reverse order: the value read is
    // the address asked for, so every answer says whose it is.
    FakeUpstream reverse(io, [&held](FakeUpstream& server, const FakeUpstream::Request& r) {
        if (r.pdu[0] != 0x03 || r.pdu[1] != 0x01) {  // not ours (a state poll): refuse quickly
            server.send(r.transaction_id, r.unit, Bytes{static_cast<std::uint8_t>(r.pdu[0] | 0x80), 0x02});
            return;
        }
        held.push_back(r);
        if (held.size() < 3) return;
        for (auto it = held.rbegin(); it != held.rend(); ++it) {
            server.send(it->transaction_id, it->unit, Bytes{0x03, 0x02, it->pdu[1], it->pdu[2]});
        }
        held.clear();
    });
    auto cfg = config_for(reverse.port());
    cfg.poll_period = std::chrono::hours{1};
    UpstreamTuning tuning;
    tuning.window = 3;
    UpstreamTarget target(io, cfg, CapturedLog{}.sink(), tuning);
    target.start();
    REQUIRE(run_until(io, [&] { return target.link_state() == LinkState::up; }));
    REQUIRE(run_until(io, [&] { return target.stats().poll_cycles >= 1; }));
    for (int round = 0; round < 5; ++round) {
        std::vector<std::shared_ptr<Answer>> answers;
        for (std::uint8_t i = 0; i < 3; ++i) {
            answers.push_back(std::make_shared<Answer>());
            target.handle(core::UnitId{10}, Bytes{0x03, 0x01, static_cast<std::uint8_t>(0x10 + i), 0x00, 0x01},
                          client(static_cast<std::uint64_t>(i % 2 + 1)), capture(answers.back()));
        }
        REQUIRE(run_until(io, [&] {
            return std::all_of(answers.begin(), answers.end(), [](const auto& a) { return a->done; });
        }));
        for (std::uint8_t i = 0; i < 3; ++i) {
            CHECK(answers[i]->pdu == Bytes{0x03, 0x02, 0x01, static_cast<std::uint8_t>(0x10 + i)});
        }
    }
    // Gateway unit 10 went out as upstream unit 1, and no two outstanding requests
    // shared a transaction ID.
    for (const auto& r : reverse.requests()) CHECK(r.unit == 1);
    CHECK(reverse.requests().size() >= 15);
}

TEST_CASE("answered locally: unknown unit, not started, malformed PDU, upstream down") {
    asio::io_context io;
    const std::uint16_t closed_port = free_port();
    auto cfg = config_for(closed_port);
    UpstreamTarget target(io, cfg, CapturedLog{}.sink());
    auto not_started = std::make_shared<Answer>();
    target.handle(core::UnitId{10}, mode_read, client(1), capture(not_started));
    target.start();
    auto unknown = std::make_shared<Answer>();
    target.handle(core::UnitId{11}, mode_read, client(1), capture(unknown));
    auto malformed = std::make_shared<Answer>();
    target.handle(core::UnitId{10}, hex("10 08 83 00 02 04 00"), client(1), capture(malformed));
    REQUIRE(run_until(io, [&] { return not_started->done && unknown->done && malformed->done; }));
    CHECK(not_started->pdu == hex("83 0A"));
    CHECK(unknown->pdu == hex("83 0A"));
    CHECK(malformed->pdu == hex("90 03"));
    // Nobody listens: the link backs off and requests are refused at once, 0x0A.
    REQUIRE(run_until(io, [&] { return target.link_state() == LinkState::backoff; }));
    auto down = std::make_shared<Answer>();
    target.handle(core::UnitId{10}, mode_read, client(1), capture(down));
    REQUIRE(run_until(io, [&] { return down->done; }));
    CHECK(down->pdu == hex("83 0A"));
    REQUIRE(target.state(core::UnitId{10}));
    CHECK_FALSE(target.state(core::UnitId{10})->online);
    CHECK_FALSE(target.state(core::UnitId{11}));
}

TEST_CASE("consecutive timeouts re-establish the connection") {
    asio::io_context io;
    FakeUpstream silent(io, [](FakeUpstream&, const FakeUpstream::Request&) {});
    auto cfg = config_for(silent.port());
    cfg.response_timeout = milliseconds{50};
    CapturedLog log;
    UpstreamTarget target(io, cfg, log.sink());
    target.start();
    REQUIRE(run_until(io, [&] { return silent.connections() >= 2; }, milliseconds{5000}));
    CHECK(log.contains("in a row got no reply"));
    CHECK(target.stats().timeouts >= 3);
}

TEST_CASE("destroyed with requests outstanding: every handler answered once, nothing touched after") {
    asio::io_context io;
    FakeUpstream silent(io, [](FakeUpstream&, const FakeUpstream::Request&) {});
    std::vector<std::shared_ptr<Answer>> answers;
    int state_reports_after = 0;
    {
        auto cfg = config_for(silent.port());
        UpstreamTuning tuning;
        tuning.window = 2;
        auto target = std::make_unique<UpstreamTarget>(io, cfg, CapturedLog{}.sink(), tuning);
        target->start();
        REQUIRE(run_until(io, [&] { return target->link_state() == LinkState::up; }));
        for (int i = 0; i < 5; ++i) {
            answers.push_back(std::make_shared<Answer>());
            target->handle(core::UnitId{10}, mode_read, client(1), capture(answers.back()));
        }
        run_for(io, milliseconds{20});  // two in flight, the rest queued
        target->set_state_callback([&state_reports_after](const R6State&) { ++state_reports_after; });
        target.reset();
    }
    CHECK(state_reports_after == 0);
    run_for(io, milliseconds{200});  // queued handlers of the dead target run now
    for (const auto& a : answers) {
        CHECK(a->done);
        CHECK(a->calls == 1);
        CHECK(a->pdu == hex("83 0A"));
    }
    // And while still connecting.
    {
        auto target = std::make_unique<UpstreamTarget>(io, config_for(silent.port()), CapturedLog{}.sink());
        target->start();
        auto a = std::make_shared<Answer>();
        target->handle(core::UnitId{10}, mode_read, client(1), capture(a));
        target.reset();
        REQUIRE(run_until(io, [&] { return a->done; }));
        CHECK(a->pdu == hex("83 0A"));
    }
    run_for(io, milliseconds{50});
}

TEST_CASE("a reply that does not fit its request is answered 0x04, counted and logged, never passed on") {
    asio::io_context io;
    // Reads of 0x0100 get a broken reply, chosen by the quantity asked; anything else
    // (state polls) a refusal.
    FakeUpstream broken(io, [](FakeUpstream& server, const FakeUpstream::Request& r) {
        if (r.pdu[0] == 0x03 && r.pdu[1] == 0x01 && r.pdu[2] == 0x00) {
            switch (r.pdu[4]) {
                case 1: server.send(r.transaction_id, r.unit, hex("83 02 00 00")); return;  // 4-byte exception
                case 2: {
                    Bytes hundred{0x03, 200};
                    hundred.resize(202, 0x11);
                    server.send(r.transaction_id, r.unit, hundred);  // 100 registers for 2
                    return;
                }
                case 3: server.send(r.transaction_id, r.unit, hex("03 FA 00 01")); return;  // byte count 250
                default: server.send(r.transaction_id, r.unit, hex("03 08 00 01 00 02 00 03 00 04")); return;
            }
        }
        if (r.pdu[0] == 0x06) {
            server.send(r.transaction_id, r.unit, hex("06 4E E8 00 63"));  // echoes another value
            return;
        }
        server.send(r.transaction_id, r.unit, Bytes{static_cast<std::uint8_t>(r.pdu[0] | 0x80), 0x02});
    });
    auto cfg = config_for(broken.port());
    cfg.poll_period = std::chrono::hours{1};
    CapturedLog log;
    UpstreamTarget target(io, cfg, log.sink());
    target.start();
    REQUIRE(run_until(io, [&] { return target.link_state() == LinkState::up; }));
    std::vector<std::shared_ptr<Answer>> answers;
    for (const char* request : {"03 01 00 00 01", "03 01 00 00 02", "03 01 00 00 03", "03 01 00 00 04",
                                "06 4E E8 00 64"}) {
        answers.push_back(std::make_shared<Answer>());
        target.handle(core::UnitId{10}, hex(request), client(1), capture(answers.back()));
    }
    REQUIRE(run_until(io, [&] {
        return std::all_of(answers.begin(), answers.end(), [](const auto& a) { return a->done; });
    }, milliseconds{5000}));
    CHECK(answers[0]->pdu == hex("83 04"));
    CHECK(answers[1]->pdu == hex("83 04"));
    CHECK(answers[2]->pdu == hex("83 04"));
    CHECK(answers[3]->pdu == hex("03 08 00 01 00 02 00 03 00 04"));  // a good reply passes unchanged
    CHECK(answers[4]->pdu == hex("86 04"));
    CHECK(target.stats().malformed_replies == 4);
    CHECK(log.contains("malformed reply"));
}
