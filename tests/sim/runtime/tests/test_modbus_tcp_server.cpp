#include <doctest/doctest.h>

#include <thread>

#include <asio/connect.hpp>
#include <asio/post.hpp>
#include <asio/read.hpp>
#include <asio/write.hpp>

#include "modbus_tcp_server.hpp"
#include "null_log.hpp"

namespace fieldbridge::sim::runtime {
namespace {

using protocol::Bytes;

using test::null_log;

/// A server on an ephemeral loopback port, run on its own thread for the test.
struct Running {
    explicit Running(std::optional<std::uint8_t> unit)
        : server(io, asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0), unit,
                 [this](protocol::ByteView pdu, Clock::time_point) {
                     seen.emplace_back(pdu.begin(), pdu.end());
                     // R6 manual 004, 3.1.1: version length 0x29.
                     return Bytes{0x03, 0x02, 0x00, 0x29};
                 },
                 null_log()) {
        server.open();
        port = server.local_endpoint().port();
        thread = std::thread([this] { io.run(); });
    }
    ~Running() {
        asio::post(io, [this] { server.close(); });
        io.stop();
        thread.join();
    }
    asio::io_context io;
    std::vector<Bytes> seen;  // written by the server thread, read after join or by the client after a reply
    ModbusTcpServer server;
    std::uint16_t port = 0;
    std::thread thread;
};

Bytes exchange(std::uint16_t port, const Bytes& request, std::size_t reply_size) {
    asio::io_context client_io;
    asio::ip::tcp::socket socket(client_io);
    socket.connect(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
    asio::write(socket, asio::buffer(request));
    Bytes reply(reply_size);
    asio::read(socket, asio::buffer(reply));
    return reply;
}

}  // namespace

TEST_CASE("R6 server: MBAP request answered with the same transaction and unit id") {
    Running running(std::nullopt);
    // Manual 004, 3.1.1 request with transaction id 0x1234 and unit 7.
    const Bytes request{0x12, 0x34, 0x00, 0x00, 0x00, 0x06, 0x07, 0x03, 0x00, 0x00, 0x00, 0x01};
    const auto reply = exchange(running.port, request, 11);
    CHECK(reply == Bytes{0x12, 0x34, 0x00, 0x00, 0x00, 0x05, 0x07, 0x03, 0x02, 0x00, 0x29});
}

TEST_CASE("R6 server: pipelined requests in one segment are answered in order") {
    Running running(std::nullopt);
    Bytes two{0x00, 0x01, 0x00, 0x00, 0x00, 0x06, 0x01, 0x03, 0x00, 0x00, 0x00, 0x01};
    const Bytes second{0x00, 0x02, 0x00, 0x00, 0x00, 0x06, 0x01, 0x03, 0x00, 0x00, 0x00, 0x01};
    two.insert(two.end(), second.begin(), second.end());
    const auto reply = exchange(running.port, two, 22);
    CHECK(reply[1] == 0x01);
    CHECK(reply[12] == 0x02);
}

TEST_CASE("R6 server: a unit filter answers other units with exception 0x0B") {
    Running running(std::uint8_t{1});
    const Bytes request{0x00, 0x09, 0x00, 0x00, 0x00, 0x06, 0x05, 0x03, 0x00, 0x00, 0x00, 0x01};
    const auto reply = exchange(running.port, request, 9);
    CHECK(reply == Bytes{0x00, 0x09, 0x00, 0x00, 0x00, 0x03, 0x05, 0x83, 0x0B});
}

TEST_CASE("R6 server: a bad protocol id closes the connection") {
    Running running(std::nullopt);
    asio::io_context client_io;
    asio::ip::tcp::socket socket(client_io);
    socket.connect(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), running.port));
    const Bytes bad{0x00, 0x01, 0x00, 0x07, 0x00, 0x06, 0x01, 0x03, 0x00, 0x00, 0x00, 0x01};
    asio::write(socket, asio::buffer(bad));
    std::array<std::uint8_t, 16> buffer{};
    asio::error_code ec;
    const auto n = socket.read_some(asio::buffer(buffer), ec);
    CHECK(n == 0);
    CHECK(ec == asio::error::eof);
}

}  // namespace fieldbridge::sim::runtime
