// Listening: every configured address, the bound port, and bind failures that say
// what to do.
#include <doctest/doctest.h>

#include <asio/ip/tcp.hpp>

#include "northbound/modbus_tcp/listen_socket.hpp"
#include "northbound/modbus_tcp/modbus_tcp_error.hpp"
#include "test_support.hpp"

namespace fieldbridge::northbound::modbus_tcp::test {
namespace {

[[nodiscard]] bool ipv6_loopback_available() {
    asio::io_context io;
    asio::ip::tcp::acceptor probe(io);
    asio::error_code error;
    probe.open(asio::ip::tcp::v6(), error);
    if (!error) probe.bind(asio::ip::tcp::endpoint(asio::ip::address_v6::loopback(), 0), error);
    return !error;
}

[[nodiscard]] std::shared_ptr<const config::ModbusTcpConfig> shared(config::ModbusTcpConfig config) {
    return std::make_shared<const config::ModbusTcpConfig>(std::move(config));
}

TEST_CASE("port 0 binds a free port and port() reports it") {
    asio::io_context io;
    ModbusTcpServer server(io, shared(loopback_config()), {});
    CHECK(server.port() == 0);
    server.start();
    CHECK(server.running());
    CHECK(server.port() != 0);
    REQUIRE(server.local_endpoints().size() == 1);
    CHECK(server.local_endpoints()[0].address().to_string() == "127.0.0.1");
    server.stop();
    CHECK_FALSE(server.running());
    CHECK(server.port() == 0);
}

TEST_CASE("a port in use fails start() with advice, and nothing stays open") {
    asio::io_context io;
    ModbusTcpServer first(io, shared(loopback_config()), {});
    first.start();
    auto config = loopback_config();
    config.listen = {config::ListenAddress{"127.0.0.1", 0}, config::ListenAddress{"127.0.0.1", first.port()}};
    ModbusTcpServer second(io, shared(config), {});
    try {
        second.start();
        FAIL("start() must throw");
    } catch (const ModbusTcpError& e) {
        const std::string message = e.what();
        CHECK(message.find("127.0.0.1:" + std::to_string(first.port())) != std::string::npos);
        CHECK(message.find("another process listens") != std::string::npos);
    }
    CHECK_FALSE(second.running());
}

TEST_CASE("listen advice names the privileged-port capability and foreign addresses") {
    const config::ListenAddress low{"0.0.0.0", 502};
    CHECK(listen_advice(asio::error::access_denied, low).find("CAP_NET_BIND_SERVICE") != std::string::npos);
    CHECK(listen_advice(asio::error_code(EADDRNOTAVAIL, asio::system_category()), config::ListenAddress{"10.9.9.9", 1502})
              .find("not an address of this machine") != std::string::npos);
}

TEST_CASE("an address that is not on this machine fails with that advice") {
    asio::io_context io;
    auto config = loopback_config();
    config.listen = {config::ListenAddress{"192.0.2.1", 0}};  // TEST-NET-1, never local
    ModbusTcpServer server(io, shared(config), {});
    CHECK_THROWS_WITH_AS(server.start(), doctest::Contains("not an address of this machine"), ModbusTcpError);
}

TEST_CASE("IPv4 and IPv6 listeners on one port both bind and both serve") {
    if (!ipv6_loopback_available()) {
        MESSAGE("IPv6 loopback unavailable; skipped");
        return;
    }
    asio::io_context io;
    {
        // Find a port free on both families.
        ModbusTcpServer probe(io, shared(loopback_config()), {});
        probe.start();
        const auto port = probe.port();
        probe.stop();
        auto config = loopback_config();
        config.listen = {config::ListenAddress{"0.0.0.0", port}, config::ListenAddress{"::", port}};
        ModbusTcpServer server(io, shared(config), {});
        server.start();
        const auto endpoints = server.local_endpoints();
        REQUIRE(endpoints.size() == 2);
        CHECK(endpoints[0].port() == port);
        CHECK(endpoints[1].port() == port);
        CHECK(endpoints[1].address().is_v6());
    }
}

/// A socket listening on a free loopback port, as systemd would pass it: the fd is
/// released to the caller.
[[nodiscard]] InheritedListener listening_socket(asio::io_context& io) {
    asio::ip::tcp::acceptor acceptor(io, asio::ip::tcp::endpoint(asio::ip::address_v4::loopback(), 0));
    const auto port = acceptor.local_endpoint().port();
    return InheritedListener{config::ListenAddress{"127.0.0.1", port}, acceptor.release()};
}

/// The loopback configuration listening only on @p inherited's address.
[[nodiscard]] config::ModbusTcpConfig listening_on(const InheritedListener& inherited) {
    auto config = loopback_config();
    config.listen = {inherited.address};
    return config;
}

[[nodiscard]] bool accepts_connections(asio::io_context& io, ModbusTcpServer& server, std::uint16_t port) {
    asio::ip::tcp::socket client(io);
    asio::error_code error;
    client.connect(asio::ip::tcp::endpoint(asio::ip::address_v4::loopback(), port), error);
    if (error) return false;
    // The server's accept runs on the loop: run it until it counted the connection.
    const auto before = server.stats().connections_accepted;
    const auto deadline = std::chrono::steady_clock::now() + wait_limit;
    while (server.stats().connections_accepted == before && std::chrono::steady_clock::now() < deadline) {
        io.run_for(std::chrono::milliseconds{10});
    }
    return server.stats().connections_accepted > before;
}

TEST_CASE("an adopted socket is served instead of binding its address, across stop and start") {
    asio::io_context io;
    const auto inherited = listening_socket(io);
    const auto port = inherited.address.port;
    ModbusTcpServer server(io, shared(listening_on(inherited)), {});
    server.adopt(inherited);
    // Binding 127.0.0.1:port would fail: the adopted socket listens there.
    server.start();
    CHECK(server.port() == port);
    CHECK(accepts_connections(io, server, port));
    server.stop();
    server.start();
    CHECK(accepts_connections(io, server, port));
}

TEST_CASE("a reload keeps an adopted socket, and one that drops its address can bring it back") {
    asio::io_context io;
    const auto inherited = listening_socket(io);
    const auto port = inherited.address.port;
    const auto config = listening_on(inherited);
    std::vector<std::string> lines;
    engine::LogSink sink{[&](engine::LogLevel, std::string_view line) { lines.emplace_back(line); }};
    ModbusTcpServer server(io, shared(config), sink);
    server.adopt(inherited);
    server.start();

    auto more = config;
    more.listen.push_back(config::ListenAddress{"127.0.0.1", 0});
    server.apply(shared(more));
    CHECK(server.local_endpoints().size() == 2);
    CHECK(accepts_connections(io, server, port));

    auto dropped = config;
    dropped.listen = {config::ListenAddress{"127.0.0.1", 0}};
    server.apply(shared(dropped));
    REQUIRE(server.local_endpoints().size() == 1);
    CHECK(server.port() != port);
    bool warned = false;
    for (const auto& line : lines) {
        warned = warned || line.find("no longer accepting on 127.0.0.1:" + std::to_string(port) +
                                     "; its socket came from systemd and stays open") != std::string::npos;
    }
    CHECK(warned);

    server.apply(shared(config));  // back: served from the adopted socket again, not bound
    CHECK(server.port() == port);
    CHECK(accepts_connections(io, server, port));
}

TEST_CASE("reload: prepare() refuses a port in use with nothing changed; a prepared change keeps unchanged listeners") {
    asio::io_context io;
    ModbusTcpServer other(io, shared(loopback_config()), {});
    other.start();
    ModbusTcpServer server(io, shared(loopback_config()), {});  // 127.0.0.1:0
    server.start();
    const auto kept = server.local_endpoints();
    REQUIRE(kept.size() == 1);

    auto busy = loopback_config();
    busy.listen.push_back(config::ListenAddress{"127.0.0.1", other.port()});
    CHECK_THROWS_AS(server.prepare(busy), ModbusTcpError);
    CHECK(server.local_endpoints() == kept);
    CHECK(accepts_connections(io, server, kept[0].port()));

    auto more = loopback_config();
    more.listen.push_back(config::ListenAddress{"127.0.0.1", 0});  // a second one, any port
    REQUIRE(more.listen.size() == 2);
    more.listen[1].host = "127.0.0.2";
    server.prepare(more);
    CHECK(server.local_endpoints() == kept);  // bound, not serving yet
    server.apply(shared(more));
    REQUIRE(server.local_endpoints().size() == 2);
    CHECK(server.local_endpoints()[0] == kept[0]);  // the same socket
    CHECK(server.local_endpoints()[1].address().to_string() == "127.0.0.2");

    auto third = loopback_config();
    third.listen.push_back(config::ListenAddress{"127.0.0.3", 0});
    server.prepare(third);
    server.abandon_prepared();  // a rejected reload: nothing changes
    CHECK(server.local_endpoints().size() == 2);
    CHECK(server.local_endpoints()[0] == kept[0]);
}

TEST_CASE("client addresses map to the configuration's form") {
    CHECK(to_ip_address(asio::ip::make_address("127.0.0.1")) == *config::parse_ip_address("127.0.0.1"));
    CHECK(to_ip_address(asio::ip::make_address("::ffff:10.1.2.3")) == *config::parse_ip_address("10.1.2.3"));
    CHECK(to_ip_address(asio::ip::make_address("fd00::5")) == *config::parse_ip_address("fd00::5"));
    CHECK(to_string(asio::ip::tcp::endpoint(asio::ip::make_address("::1"), 502)) == "[::1]:502");
    CHECK(to_string(asio::ip::tcp::endpoint(asio::ip::make_address("10.0.0.1"), 1502)) == "10.0.0.1:1502");
}

}  // namespace
}  // namespace fieldbridge::northbound::modbus_tcp::test
