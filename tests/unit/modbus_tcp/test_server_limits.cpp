// Connection limits, idle timeout, backpressure, slow readers, allow-list, and what
// targets see when a connection closes.
#include <doctest/doctest.h>

#include <memory>
#include <set>

#include "fake_targets.hpp"
#include "test_support.hpp"

namespace fieldbridge::northbound::modbus_tcp::test {
namespace {

template <class T>
T& target(Harness& h, std::size_t index = 0) {
    return dynamic_cast<T&>(*h.targets.at(index));
}

TEST_CASE("beyond max_connections new connections are closed at once; the others work") {
    auto config = loopback_config();
    config.max_connections = 64;
    config.max_connections_per_client = 1024;  // all of them come from 127.0.0.1
    Harness h(config, {}, [](Harness& self) { self.add_target<ImmediateTarget>({1}); });
    constexpr std::size_t attempts = 500;
    std::vector<std::unique_ptr<Client>> clients;
    for (std::size_t i = 0; i < attempts; ++i) clients.push_back(std::make_unique<Client>(h.port));
    REQUIRE(h.wait_for_stats([](const ServerStats& s) {
        return s.connections_accepted + s.refused_max_connections == attempts;
    }, 20s));
    auto stats = h.stats();
    CHECK(stats.connections_open == 64);
    CHECK(stats.refused_max_connections == attempts - 64);
    std::size_t closed = 0;
    std::size_t answered = 0;
    for (std::size_t i = 0; i < attempts; ++i) {
        if (clients[i]->closed_within(0ms)) {
            ++closed;
            continue;
        }
        const auto response = clients[i]->ask(read_registers(static_cast<std::uint16_t>(i), 1, 0, 1));
        if (response && response->transaction_id == i) ++answered;
    }
    CHECK(closed == attempts - 64);
    CHECK(answered == 64);
    // Refusals are logged, but not one line each.
    const auto lines = h.log_lines();
    const auto refusal_lines = std::count_if(lines.begin(), lines.end(), [](const std::string& line) {
        return line.find("max_connections") != std::string::npos;
    });
    CHECK(refusal_lines >= 1);
    CHECK(refusal_lines < 10);
    // A freed place is taken by the next client.
    clients.clear();
    REQUIRE(h.wait_for_stats([](const ServerStats& s) { return s.connections_open == 0; }));
    Client again(h.port);
    CHECK(again.ask(read_registers(1, 1, 0, 1)));
}

TEST_CASE("a client outside the allow-list is closed at accept") {
    auto config = loopback_config();
    config.allow = {cidr("10.0.0.0/8")};
    Harness h(config, {}, [](Harness& self) { self.add_target<ImmediateTarget>({1}); });
    Client client(h.port);
    CHECK(client.closed_within(wait_limit));
    CHECK(h.wait_for_stats([](const ServerStats& s) { return s.refused_not_allowed == 1; }));
    CHECK(h.stats().connections_accepted == 0);
    const auto lines = h.log_lines();
    CHECK(std::any_of(lines.begin(), lines.end(), [](const std::string& line) {
        return line.find("refused 127.0.0.1:") != std::string::npos && line.find("allow") != std::string::npos;
    }));
}

TEST_CASE("a reload that removes a client from the allow-list closes its connection") {
    Harness h(loopback_config(), {}, [](Harness& self) { self.add_target<ImmediateTarget>({1}); });
    Client client(h.port);
    REQUIRE(client.ask(read_registers(1, 1, 0, 1)));
    auto reloaded = loopback_config();
    reloaded.allow = {cidr("10.0.0.0/8")};
    h.on_loop([&] {
        h.server->apply(std::make_shared<const config::ModbusTcpConfig>(reloaded));
        return 0;
    });
    CHECK(client.closed_within(wait_limit));
    CHECK(h.stats().connections_open == 0);
}

TEST_CASE("idle connections close after idle_timeout; an incomplete frame counts as malformed") {
    auto config = loopback_config();
    config.idle_timeout = std::chrono::milliseconds{200};
    Harness h(config, {}, [](Harness& self) { self.add_target<SilentTarget>({1}); });
    Client waiting(h.port);  // has a request with the target: not idle
    REQUIRE(waiting.send(read_registers(5, 1, 0, 1)));
    REQUIRE(h.wait_for_stats([](const ServerStats& s) { return s.requests == 1; }));
    Client idle(h.port);
    Client partial(h.port);
    REQUIRE(partial.send(Bytes{0x00, 0x01, 0x00}));
    CHECK(idle.closed_within(wait_limit));
    CHECK(partial.closed_within(wait_limit));
    CHECK(h.wait_for_stats([](const ServerStats& s) { return s.closed_idle == 1 && s.closed_malformed == 1; }));
    CHECK_FALSE(waiting.closed_within(300ms));
    CHECK(h.on_loop([&] { return target<SilentTarget>(h).answer_all(); }) == 1);
    const auto response = waiting.receive();
    REQUIRE(response);
    CHECK(response->transaction_id == 5);
    CHECK(waiting.closed_within(wait_limit));  // idle again once answered
    CHECK(h.wait_for_stats([](const ServerStats& s) { return s.closed_idle == 2; }));
}

TEST_CASE("a frame not complete within frame_timeout of its first byte closes the connection") {
    auto config = loopback_config();
    config.frame_timeout = std::chrono::milliseconds{300};
    Harness h(config, {}, [](Harness& self) { self.add_target<ImmediateTarget>({1}); });
    Client slow(h.port);
    Client good(h.port);
    REQUIRE(slow.send(Bytes{0x00, 0x01, 0x00}));
    const auto sent_at = std::chrono::steady_clock::now();
    CHECK(good.ask(read_registers(1, 1, 0, 1)));  // others are not held up
    CHECK(slow.closed_within(wait_limit));
    CHECK(std::chrono::steady_clock::now() - sent_at >= 250ms);
    CHECK(h.wait_for_stats([](const ServerStats& s) { return s.closed_frame_timeout == 1; }));
    const auto lines = h.log_lines();
    CHECK(std::any_of(lines.begin(), lines.end(), [](const std::string& line) {
        return line.find("frame_timeout") != std::string::npos && line.find("127.0.0.1:") != std::string::npos;
    }));
    // Complete frames, however many and however split, never meet the deadline.
    Client busy(h.port);
    const Bytes request = read_registers(9, 1, 4, 1);
    for (int i = 0; i < 8; ++i) {
        REQUIRE(busy.send(ByteView(request).first(5)));
        REQUIRE(busy.send(ByteView(request).subspan(5)));
        const auto response = busy.receive();
        REQUIRE(response);
        CHECK(response->transaction_id == 9);
    }
    CHECK_FALSE(busy.closed_within(400ms));
}

TEST_CASE("bytes of an incomplete frame do not reset the idle timeout") {
    auto config = loopback_config();
    config.idle_timeout = std::chrono::milliseconds{300};
    config.frame_timeout = std::chrono::seconds{60};
    Harness h(config, {}, [](Harness& self) { self.add_target<ImmediateTarget>({1}); });
    Client trickle(h.port);
    // One byte every 50 ms of a 12-byte frame: it would complete after 550 ms.
    const Bytes request = read_registers(1, 1, 0, 1);
    std::size_t sent = 0;
    for (; sent < request.size(); ++sent) {
        if (!trickle.send(ByteView(request).subspan(sent, 1)) || trickle.closed_within(50ms)) break;
    }
    CHECK(sent < request.size());
    CHECK(trickle.closed_within(wait_limit));
}

TEST_CASE("beyond max_connections_per_client one address's new connections are refused") {
    auto config = loopback_config();
    config.max_connections_per_client = 2;
    Harness h(config, {}, [](Harness& self) { self.add_target<ImmediateTarget>({1}); });
    auto first = std::make_unique<Client>(h.port);
    Client second(h.port);
    REQUIRE(h.wait_for_stats([](const ServerStats& s) { return s.connections_accepted == 2; }));
    Client third(h.port);
    CHECK(third.closed_within(wait_limit));
    CHECK(h.wait_for_stats([](const ServerStats& s) { return s.refused_per_client == 1; }));
    CHECK(second.ask(read_registers(1, 1, 0, 1)));
    const auto lines = h.log_lines();
    CHECK(std::any_of(lines.begin(), lines.end(), [](const std::string& line) {
        return line.find("max_connections_per_client") != std::string::npos;
    }));
    first.reset();  // a freed place is taken by the next connection from that address
    REQUIRE(h.wait_for_stats([](const ServerStats& s) { return s.connections_open == 1; }));
    Client again(h.port);
    CHECK(again.ask(read_registers(2, 1, 0, 1)));
}

TEST_CASE("idle_timeout 0 never closes") {
    auto config = loopback_config();
    config.idle_timeout = std::chrono::milliseconds{0};
    Harness h(config, {}, [](Harness& self) { self.add_target<ImmediateTarget>({1}); });
    Client client(h.port);
    CHECK_FALSE(client.closed_within(300ms));
    CHECK(client.ask(read_registers(1, 1, 0, 1)));
}

TEST_CASE("at max_outstanding the connection stops reading until a request is answered") {
    ServerLimits limits;
    limits.max_outstanding = 4;
    Harness h(loopback_config(), limits, [](Harness& self) { self.add_target<SilentTarget>({1}); });
    Client client(h.port);
    Bytes batch;
    for (std::uint16_t id = 0; id < 10; ++id) {
        const Bytes one = read_registers(id, 1, id, 1);
        batch.insert(batch.end(), one.begin(), one.end());
    }
    REQUIRE(client.send(batch));
    REQUIRE(h.wait_for_stats([](const ServerStats& s) { return s.requests == 4; }));
    std::set<std::uint16_t> answered;
    for (int round = 0; round < 10 && answered.size() < 10; ++round) {
        // Whatever the timing, the target never holds more than the limit.
        const auto held = h.on_loop([&] { return target<SilentTarget>(h).holding(); });
        CHECK(held <= 4);
        const auto released = h.on_loop([&] { return target<SilentTarget>(h).answer_all(); });
        for (std::size_t i = 0; i < released; ++i) {
            const auto response = client.receive();
            REQUIRE(response);
            answered.insert(response->transaction_id);
        }
        if (answered.size() < 10) {
            const auto expected = std::min<std::size_t>(10, answered.size() + 4);
            REQUIRE(h.wait_for_stats([expected](const ServerStats& s) { return s.requests == expected; }));
        }
    }
    CHECK(answered.size() == 10);
}

TEST_CASE("a client that never reads does not delay another; it is closed when its output backs up") {
    Harness h(loopback_config(), {}, [](Harness& self) { self.add_target<ImmediateTarget>({1}); });
    Client stalled(h.port, 4096);
    Client other(h.port);
    // 125-register reads: 12 request bytes in, 259 response bytes out.
    Bytes batch;
    for (int i = 0; i < 256; ++i) {
        const Bytes one = read_registers(static_cast<std::uint16_t>(i), 1, 0, 125);
        batch.insert(batch.end(), one.begin(), one.end());
    }
    bool stalled_closed = false;
    std::uint16_t id = 0;
    for (int round = 0; round < 2000 && !stalled_closed; ++round) {
        if (!stalled.send(batch, 1s)) {
            stalled_closed = stalled.closed_within(wait_limit);
            if (!stalled_closed) continue;  // only slowed down by flow control
        }
        ++id;
        const auto response = other.ask(read_registers(id, 1, 7, 2));
        REQUIRE(response);
        CHECK(response->transaction_id == id);
    }
    CHECK(stalled_closed);
    CHECK(h.wait_for_stats([](const ServerStats& s) { return s.closed_output_overflow == 1; }));
    CHECK(other.ask(read_registers(1, 1, 0, 1)));
}

TEST_CASE("targets that saw a connection are told when it closes; answers after the close are dropped") {
    Harness h(loopback_config(), {}, [](Harness& self) {
        self.add_target<DelayedTarget>({1}, /*answer_closed=*/true);
        self.add_target<SilentTarget>({2});
    });
    std::uint64_t connection = 0;
    {
        Client client(h.port);
        REQUIRE(client.send(read_registers(1, 1, 200, 1)));  // answered 200 ms later
        REQUIRE(client.send(read_registers(2, 2, 0, 1)));    // never answered
        REQUIRE(h.wait_for_stats([](const ServerStats& s) { return s.requests == 2; }));
        connection = h.on_loop([&] { return target<SilentTarget>(h, 1).clients.at(0).connection; });
    }
    REQUIRE(h.wait_for_stats([](const ServerStats& s) { return s.connections_open == 0; }));
    CHECK(h.on_loop([&] { return target<DelayedTarget>(h, 0).closed; }) == std::vector<std::uint64_t>{connection});
    CHECK(h.on_loop([&] { return target<SilentTarget>(h, 1).closed; }) == std::vector<std::uint64_t>{connection});
    CHECK(h.on_loop([&] { return target<SilentTarget>(h, 1).holding(); }) == 0);
    CHECK(h.wait_for_stats([](const ServerStats& s) { return s.late_responses == 1; }));
    CHECK(h.stats().responses == 0);
}

TEST_CASE("a connection that sent nothing to targets does not bother them when it closes") {
    Harness h(loopback_config(), {}, [](Harness& self) { self.add_target<ImmediateTarget>({1}); });
    { Client client(h.port); }
    REQUIRE(h.wait_for_stats([](const ServerStats& s) { return s.connections_accepted == 1 && s.connections_open == 0; }));
    CHECK(h.on_loop([&] { return target<ImmediateTarget>(h).closed.size(); }) == 0);
}

TEST_CASE("stopping the server with requests in flight: targets are told, nothing is answered late") {
    auto h = std::make_unique<Harness>(loopback_config(), ServerLimits{},
                                       [](Harness& self) { self.add_target<DelayedTarget>({1}, true); });
    Client client(h->port);
    REQUIRE(client.send(read_registers(1, 1, 100, 1)));
    REQUIRE(h->wait_for_stats([](const ServerStats& s) { return s.requests == 1; }));
    h->on_loop([&] {
        h->server->stop();
        return 0;
    });
    CHECK(client.closed_within(wait_limit));
    CHECK(h->on_loop([&] { return target<DelayedTarget>(*h).closed.size(); }) == 1);
    h.reset();  // the target's timer is cancelled on the loop; ASan checks the rest
}

}  // namespace
}  // namespace fieldbridge::northbound::modbus_tcp::test
