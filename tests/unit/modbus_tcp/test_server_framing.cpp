// The server over real loopback sockets: MBAP framing, pipelining, local exceptions.
#include <doctest/doctest.h>

#include "fake_targets.hpp"
#include "protocol/modbus_pdu.hpp"
#include "test_support.hpp"

namespace fieldbridge::northbound::modbus_tcp::test {
namespace {

/// The FC03 response the register bank gives for registers never written.
[[nodiscard]] Bytes bank_read(std::uint16_t address, std::uint16_t count) {
    std::vector<std::uint16_t> values;
    for (std::uint16_t i = 0; i < count; ++i) values.push_back(static_cast<std::uint16_t>(address + i));
    return protocol::encode_response(protocol::ReadRegistersResponse{0x03, values});
}

TEST_CASE("a request is answered with its transaction ID and unit") {
    Harness h(loopback_config(), {}, [](Harness& self) { self.add_target<ImmediateTarget>({5}); });
    Client client(h.port);
    const auto response = client.ask(read_registers(0xBEEF, 5, 0x0300, 2));
    REQUIRE(response);
    CHECK(response->transaction_id == 0xBEEF);
    CHECK(response->unit_id == core::UnitId{5});
    CHECK(response->pdu == bank_read(0x0300, 2));
    const auto stats = h.stats();
    CHECK(stats.requests == 1);
    CHECK(stats.responses == 1);
    CHECK(stats.connections_open == 1);
    CHECK(stats.connections_accepted == 1);
}

TEST_CASE("pipelined requests are answered in completion order, each with its own transaction ID") {
    Harness h(loopback_config(), {}, [](Harness& self) { self.add_target<DelayedTarget>({1, 2}); });
    Client client(h.port);
    // One write holding three requests: the target answers after `address` ms.
    Bytes batch = read_registers(10, 1, 300, 3);
    const Bytes second = read_registers(11, 2, 0, 2);
    const Bytes third = read_registers(12, 1, 100, 1);
    batch.insert(batch.end(), second.begin(), second.end());
    batch.insert(batch.end(), third.begin(), third.end());
    REQUIRE(client.send(batch));
    std::vector<protocol::MbapFrame> answers;
    for (int i = 0; i < 3; ++i) {
        auto frame = client.receive();
        REQUIRE(frame);
        answers.push_back(*frame);
    }
    CHECK(answers[0].transaction_id == 11);
    CHECK(answers[0].unit_id == core::UnitId{2});
    CHECK(answers[0].pdu == bank_read(0, 2));
    CHECK(answers[1].transaction_id == 12);
    CHECK(answers[1].pdu == bank_read(100, 1));
    CHECK(answers[2].transaction_id == 10);
    CHECK(answers[2].unit_id == core::UnitId{1});
    CHECK(answers[2].pdu == bank_read(300, 3));
}

TEST_CASE("requests split across many small writes are framed") {
    Harness h(loopback_config(), {}, [](Harness& self) { self.add_target<ImmediateTarget>({1}); });
    Client client(h.port);
    const Bytes request = read_registers(77, 1, 4, 1);
    for (const auto byte : request) REQUIRE(client.send(Bytes{byte}));
    const auto response = client.receive();
    REQUIRE(response);
    CHECK(response->transaction_id == 77);
    CHECK(response->pdu == bank_read(4, 1));
}

TEST_CASE("a unit without a route gets exception 0x0A and reaches no target") {
    Harness h(loopback_config(), {}, [](Harness& self) { self.add_target<ImmediateTarget>({1}); });
    Client client(h.port);
    const auto response = client.ask(read_registers(3, 9, 0, 1, 0x04));
    REQUIRE(response);
    CHECK(response->transaction_id == 3);
    CHECK(response->unit_id == core::UnitId{9});
    CHECK(response->pdu == exception_pdu(0x04, 0x0A));
    const auto stats = h.stats();
    CHECK(stats.unknown_unit == 1);
    CHECK(stats.exceptions(0x0A) == 1);
    CHECK(h.on_loop([&] { return dynamic_cast<ImmediateTarget&>(*h.targets[0]).seen.size(); }) == 0);
}

TEST_CASE("a PDU the target cannot decode is forwarded as it came; its exception is passed through") {
    Harness h(loopback_config(), {}, [](Harness& self) { self.add_target<ImmediateTarget>({1}); });
    Client client(h.port);
    const Bytes bad_count{0x03, 0x00, 0x00, 0x00, 0x00};  // quantity 0
    const auto response = client.ask(protocol::encode_mbap(8, core::UnitId{1}, bad_count));
    REQUIRE(response);
    CHECK(response->pdu == exception_pdu(0x03, 0x03));
    CHECK(h.on_loop([&] { return dynamic_cast<ImmediateTarget&>(*h.targets[0]).seen; }) == std::vector<Bytes>{bad_count});
    CHECK(h.stats().exceptions(0x03) == 1);
}

TEST_CASE("a target that throws or answers an empty PDU yields exception 0x04; the connection goes on") {
    Harness h(loopback_config(), {}, [](Harness& self) {
        self.add_target<ThrowingTarget>({1});
        self.add_target<EmptyAnswerTarget>({2});
        self.add_target<ImmediateTarget>({3});
    });
    Client client(h.port);
    auto response = client.ask(read_registers(1, 1, 0, 1));
    REQUIRE(response);
    CHECK(response->pdu == exception_pdu(0x03, 0x04));
    response = client.ask(write_register(2, 2, 0, 1));
    REQUIRE(response);
    CHECK(response->pdu == exception_pdu(0x06, 0x04));
    response = client.ask(read_registers(3, 3, 0, 1));
    REQUIRE(response);
    CHECK(response->pdu == bank_read(0, 1));
    const auto stats = h.stats();
    CHECK(stats.target_failures == 2);
    CHECK(stats.exceptions(0x04) == 2);
}

struct BadHeader {
    const char* name;
    Bytes frame;
};

TEST_CASE("a malformed MBAP header closes only that connection") {
    const std::vector<BadHeader> cases{
        {"protocol id 1", raw_frame(1, 1, 6, Bytes{1, 0x03, 0x00, 0x00, 0x00, 0x01})},
        {"length 1 (no PDU)", raw_frame(1, 0, 1, Bytes{1})},
        {"length 0", raw_frame(1, 0, 0, Bytes{})},
        {"length 255 (oversize)", raw_frame(1, 0, 255, Bytes(255, 0x03))},
        {"length 300 (oversize)", raw_frame(1, 0, 300, Bytes{1, 0x03})},
        {"length 0xFFFF", raw_frame(1, 0, 0xFFFF, Bytes{})},
    };
    for (const auto& bad : cases) {
        CAPTURE(bad.name);
        Harness h(loopback_config(), {}, [](Harness& self) { self.add_target<ImmediateTarget>({1}); });
        Client good(h.port);
        Client hostile(h.port);
        REQUIRE(good.ask(read_registers(1, 1, 0, 1)));
        REQUIRE(hostile.send(bad.frame));
        CHECK(hostile.closed_within(wait_limit));
        const auto response = good.ask(read_registers(2, 1, 5, 1));
        REQUIRE(response);
        CHECK(response->transaction_id == 2);
        CHECK(h.wait_for_stats([](const ServerStats& s) { return s.closed_malformed == 1; }));
        const auto stats = h.stats();
        CHECK(stats.connections_open == 1);
        CHECK(stats.requests == 2);
        const auto lines = h.log_lines();
        CHECK(std::any_of(lines.begin(), lines.end(), [](const std::string& line) {
            return line.find("malformed MBAP header") != std::string::npos && line.find("127.0.0.1:") != std::string::npos;
        }));
    }
}

TEST_CASE("requests ahead of a malformed header are answered before the close; nothing after it is read") {
    Harness h(loopback_config(), {}, [](Harness& self) { self.add_target<DelayedTarget>({1}); });
    Client client(h.port);
    // A write the target answers after 150 ms, a local 0x0A, the bad header, then a
    // request that must not be taken.
    Bytes stream = write_register(40, 1, 150, 7);
    for (const Bytes& next : {read_registers(41, 9, 0, 1), raw_frame(42, 7, 6, Bytes{1, 0x03, 0, 0, 0, 1}),
                              read_registers(43, 1, 0, 1)}) {
        stream.insert(stream.end(), next.begin(), next.end());
    }
    REQUIRE(client.send(stream));
    std::vector<std::uint16_t> answered;
    for (int i = 0; i < 2; ++i) {
        const auto frame = client.receive();
        REQUIRE(frame);
        answered.push_back(frame->transaction_id);
    }
    CHECK(answered == std::vector<std::uint16_t>{41, 40});
    CHECK(client.closed_within(wait_limit));
    CHECK(h.wait_for_stats([](const ServerStats& s) { return s.closed_malformed == 1 && s.requests == 2; }));
    const auto stats = h.stats();
    CHECK(stats.late_responses == 0);
    CHECK(stats.connections_open == 0);
    CHECK(h.on_loop([&] { return dynamic_cast<DelayedTarget&>(*h.targets[0]).seen.size(); }) == 1);
}

}  // namespace
}  // namespace fieldbridge::northbound::modbus_tcp::test
