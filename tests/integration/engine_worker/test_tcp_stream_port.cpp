// TcpStreamPort (issue 27) against a real loopback listener: the connect (waited for,
// or begun and finished by the caller as the worker does), bytes both ways with
// TCP_NODELAY, the server closing, a refused port and a name that does not resolve
// with what the error says.
#include <doctest/doctest.h>

#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cstdint>
#include <string>

#include "engine/tcp_stream_port.hpp"
#include "free_port.hpp"

namespace {

namespace fe = fieldbridge::engine;

/// A loopback listener on a free port; accept() takes one client.
struct Listener {
    Listener() {
        const fieldbridge::test::LoopbackListener listening = fieldbridge::test::listen_on_loopback();
        fd = listening.fd;
        port = listening.port;
    }
    ~Listener() {
        if (client >= 0) ::close(client);
        if (fd >= 0) ::close(fd);
    }
    void accept() {
        pollfd watch{fd, POLLIN, 0};
        REQUIRE(::poll(&watch, 1, 2000) == 1);
        client = ::accept(fd, nullptr, nullptr);
        REQUIRE(client >= 0);
    }
    int fd = -1;
    int client = -1;
    std::uint16_t port = 0;
};

fe::SerialSettings settings_for(const std::string& host, std::uint16_t port) {
    fe::SerialSettings settings;
    settings.path = "tcp://" + host + ":" + std::to_string(port);
    settings.tcp = fe::StreamEndpoint{host, port, std::chrono::milliseconds{1000}};
    return settings;
}

/// Reads until @p count bytes came (bounded).
std::string read_port(fe::TcpStreamPort& port, std::size_t count) {
    std::string got;
    std::array<std::uint8_t, 64> buffer{};
    for (int i = 0; i < 200 && got.size() < count; ++i) {
        pollfd watch{port.native_handle(), POLLIN, 0};
        ::poll(&watch, 1, 10);
        const std::size_t n = port.read_some(buffer);
        got.append(buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(n));
    }
    return got;
}

TEST_CASE("tcp stream port: connects (waited), carries bytes both ways, sets TCP_NODELAY and keepalive") {
    Listener server;
    fe::TcpStreamPort port(settings_for("127.0.0.1", server.port), fe::ConnectWait::block);
    port.open();
    REQUIRE(port.is_open());
    CHECK_FALSE(port.opening());
    server.accept();
    CHECK(port.open_detail() == "connected to 127.0.0.1:" + std::to_string(server.port) +
                                    " (TCP_NODELAY, keepalive 5 s)");
    int value = 0;
    socklen_t length = sizeof value;
    ::getsockopt(port.native_handle(), IPPROTO_TCP, TCP_NODELAY, &value, &length);
    CHECK(value == 1);
    ::getsockopt(port.native_handle(), SOL_SOCKET, SO_KEEPALIVE, &value, &length);
    CHECK(value == 1);

    const std::string request = "\x02\x03\x06\x00\x00\x01";
    const auto* bytes = reinterpret_cast<const std::uint8_t*>(request.data());
    CHECK(port.write_some(fieldbridge::protocol::ByteView(bytes, request.size())) == request.size());
    std::array<char, 16> seen{};
    REQUIRE(::recv(server.client, seen.data(), seen.size(), 0) == static_cast<ssize_t>(request.size()));
    REQUIRE(::send(server.client, "reply", 5, 0) == 5);
    CHECK(read_port(port, 5) == "reply");

    // The server closes: the next read says so, and what to expect.
    ::close(server.client);
    server.client = -1;
    std::string what;
    try {
        static_cast<void>(read_port(port, 1));
    } catch (const fe::SerialPortError& error) {
        what = error.what();
    }
    CHECK(what.find("tcp://127.0.0.1:" + std::to_string(server.port) + ": the device server 127.0.0.1:" +
                    std::to_string(server.port) + " closed the connection") != std::string::npos);
    CHECK_FALSE(port.is_open());
}

TEST_CASE("tcp stream port: a begun connect is finished by the caller once the socket is writable") {
    Listener server;
    fe::TcpStreamPort port(settings_for("127.0.0.1", server.port), fe::ConnectWait::begin);
    port.open();
    REQUIRE(port.is_open());
    if (port.opening()) {
        pollfd watch{port.native_handle(), POLLOUT, 0};
        REQUIRE(::poll(&watch, 1, 2000) == 1);
        port.finish_open();
    }
    CHECK_FALSE(port.opening());
    server.accept();
    CHECK(port.open_timeout() == std::chrono::milliseconds{1000});
}

TEST_CASE("tcp stream port: a refused port and a host that does not resolve say what to check") {
    std::uint16_t closed_port = 0;
    {
        Listener gone;
        closed_port = gone.port;
    }
    fe::TcpStreamPort refused(settings_for("127.0.0.1", closed_port), fe::ConnectWait::begin);
    std::string what;
    try {
        refused.open();
        if (refused.opening()) {
            pollfd watch{refused.native_handle(), POLLOUT, 0};
            REQUIRE(::poll(&watch, 1, 2000) == 1);
            refused.finish_open();
        }
    } catch (const fe::SerialPortError& error) {
        what = error.what();
    }
    CHECK(what.find("cannot connect to 127.0.0.1:" + std::to_string(closed_port) + " (Connection refused)") !=
          std::string::npos);
    CHECK(what.find("TCP server (transparent) mode") != std::string::npos);
    CHECK_FALSE(refused.is_open());

    fe::TcpStreamPort nowhere(settings_for("no-such-device-server.invalid", 4001), fe::ConnectWait::block);
    what.clear();
    try {
        nowhere.open();
    } catch (const fe::SerialPortError& error) {
        what = error.what();
    }
    CHECK(what.find("cannot resolve host 'no-such-device-server.invalid'") != std::string::npos);
    CHECK_FALSE(nowhere.is_open());
}

}  // namespace
