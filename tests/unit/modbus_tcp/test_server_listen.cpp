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

TEST_CASE("client addresses map to the configuration's form") {
    CHECK(to_ip_address(asio::ip::make_address("127.0.0.1")) == *config::parse_ip_address("127.0.0.1"));
    CHECK(to_ip_address(asio::ip::make_address("::ffff:10.1.2.3")) == *config::parse_ip_address("10.1.2.3"));
    CHECK(to_ip_address(asio::ip::make_address("fd00::5")) == *config::parse_ip_address("fd00::5"));
    CHECK(to_string(asio::ip::tcp::endpoint(asio::ip::make_address("::1"), 502)) == "[::1]:502");
    CHECK(to_string(asio::ip::tcp::endpoint(asio::ip::make_address("10.0.0.1"), 1502)) == "10.0.0.1:1502");
}

}  // namespace
}  // namespace fieldbridge::northbound::modbus_tcp::test
