// The /metrics endpoint over real loopback sockets, driven by an io_context in the
// test like the daemon's loop drives it.
#include <doctest/doctest.h>

#include <array>
#include <chrono>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include <asio/connect.hpp>
#include <asio/ip/tcp.hpp>
#include <asio/write.hpp>

#include "northbound/metrics/exposition.hpp"
#include "northbound/metrics/http_endpoint.hpp"

namespace fieldbridge::northbound::metrics {
namespace {

using namespace std::chrono_literals;

const config::ListenAddress any_loopback_port{"127.0.0.1", 0};

/// Connects to 127.0.0.1:@p port, sends @p request, and reads until the server
/// closes; runs @p io meanwhile (the endpoint lives on it). Bounded: 5 s.
[[nodiscard]] std::string exchange(asio::io_context& io, std::uint16_t port, const std::string& request) {
    asio::ip::tcp::socket socket(io);
    std::string response;
    std::array<char, 4096> buffer{};
    bool done = false;
    asio::error_code failure;
    std::function<void()> read_more = [&] {
        socket.async_read_some(asio::buffer(buffer), [&](const asio::error_code& error, std::size_t n) {
            response.append(buffer.data(), n);
            if (error) {
                if (error != asio::error::eof && error != asio::error::connection_reset) failure = error;
                done = true;
                return;
            }
            read_more();
        });
    };
    socket.async_connect({asio::ip::make_address("127.0.0.1"), port}, [&](const asio::error_code& error) {
        if (error) {
            failure = error;
            done = true;
            return;
        }
        asio::async_write(socket, asio::buffer(request), [&](const asio::error_code& write_error, std::size_t) {
            if (write_error) {
                failure = write_error;
                done = true;
                return;
            }
            read_more();
        });
    });
    const auto deadline = std::chrono::steady_clock::now() + 5s;
    while (!done && std::chrono::steady_clock::now() < deadline) io.run_one_for(50ms);
    REQUIRE_MESSAGE(done, "no complete answer within 5 s");
    REQUIRE_MESSAGE(!failure, failure.message());
    return response;
}

/// Runs @p io for @p duration (the endpoint always waits on something: it never runs out of work).
void run_for(asio::io_context& io, std::chrono::steady_clock::duration duration) {
    const auto deadline = std::chrono::steady_clock::now() + duration;
    while (std::chrono::steady_clock::now() < deadline) io.run_one_for(20ms);
}

/// A blocking client connected from @p local_host (the kernel completes the handshake
/// whether or not the server has accepted it yet).
[[nodiscard]] asio::ip::tcp::socket connect_from(asio::io_context& io, std::uint16_t port,
                                                 const std::string& local_host) {
    asio::ip::tcp::socket socket(io, asio::ip::tcp::v4());
    socket.bind({asio::ip::make_address(local_host), 0});
    socket.connect({asio::ip::make_address("127.0.0.1"), port});
    return socket;
}

/// True once the server has ended @p socket (end of stream or reset): checked without blocking.
[[nodiscard]] bool ended_by_server(asio::ip::tcp::socket& socket) {
    socket.non_blocking(true);
    std::array<char, 256> buffer{};
    asio::error_code error;
    socket.read_some(asio::buffer(buffer), error);
    return error && error != asio::error::would_block;
}

[[nodiscard]] std::string request(const std::string& method, const std::string& path) {
    return method + " " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n";
}

[[nodiscard]] std::string status_line(const std::string& response) {
    return response.substr(0, response.find("\r\n"));
}

[[nodiscard]] std::string body(const std::string& response) {
    const auto end = response.find("\r\n\r\n");
    return end == std::string::npos ? std::string() : response.substr(end + 4);
}

[[nodiscard]] bool has_header(const std::string& response, const std::string& header) {
    return response.substr(0, response.find("\r\n\r\n")).find("\r\n" + header + "\r\n") != std::string::npos;
}

[[nodiscard]] std::string sample_text() {
    MetricSet set;
    set.add_counter("fb_test_total", "A test counter", {{"line", "a"}}, 7);
    return set.render();
}

/// sample_text(), counting the calls in @p renders.
[[nodiscard]] HttpEndpoint::Render counting(int& renders) {
    return [&renders] {
        ++renders;
        return sample_text();
    };
}

TEST_CASE("GET /metrics answers 200 with the text format's content type and the rendered body") {
    asio::io_context io;
    int renders = 0;
    HttpEndpoint endpoint(io, any_loopback_port, counting(renders));
    REQUIRE(endpoint.port() != 0);
    const std::string response = exchange(io, endpoint.port(), request("GET", "/metrics"));
    CHECK(status_line(response) == "HTTP/1.1 200 OK");
    CHECK(has_header(response, "Content-Type: text/plain; version=0.0.4; charset=utf-8"));
    CHECK(body(response) == sample_text());
    CHECK(renders == 1);
    // A second scrape on a new connection works as well (the loop keeps watching).
    CHECK(body(exchange(io, endpoint.port(), request("GET", "/metrics"))) == sample_text());
    CHECK(renders == 2);
}

TEST_CASE("HEAD /metrics answers the headers without a body") {
    asio::io_context io;
    HttpEndpoint endpoint(io, any_loopback_port, sample_text);
    const std::string response = exchange(io, endpoint.port(), request("HEAD", "/metrics"));
    CHECK(status_line(response) == "HTTP/1.1 200 OK");
    CHECK(has_header(response, "Content-Type: text/plain; version=0.0.4; charset=utf-8"));
    CHECK(body(response).empty());
}

TEST_CASE("another path is 404, another method 405 with Allow, and neither renders") {
    asio::io_context io;
    int renders = 0;
    HttpEndpoint endpoint(io, any_loopback_port, counting(renders));
    const std::string not_found = exchange(io, endpoint.port(), request("GET", "/"));
    CHECK(status_line(not_found) == "HTTP/1.1 404 Not Found");
    CHECK(status_line(exchange(io, endpoint.port(), request("GET", "/metrics/x"))) == "HTTP/1.1 404 Not Found");
    const std::string not_allowed = exchange(io, endpoint.port(), request("POST", "/metrics"));
    CHECK(status_line(not_allowed) == "HTTP/1.1 405 Method Not Allowed");
    CHECK(has_header(not_allowed, "Allow: GET, HEAD"));
    CHECK(renders == 0);
}

TEST_CASE("a render that throws answers 500 with the reason, and the endpoint keeps serving") {
    asio::io_context io;
    bool fail = true;
    HttpEndpoint endpoint(io, any_loopback_port, [&fail]() -> std::string {
        if (fail) throw std::runtime_error("collector broke");
        return sample_text();
    });
    const std::string response = exchange(io, endpoint.port(), request("GET", "/metrics"));
    CHECK(status_line(response) == "HTTP/1.1 500 Internal Server Error");
    CHECK(body(response).find("collector broke") != std::string::npos);
    fail = false;
    CHECK(status_line(exchange(io, endpoint.port(), request("GET", "/metrics"))) == "HTTP/1.1 200 OK");
}

TEST_CASE("an idle connection is closed after the connection timeout (MHD's timer runs on the loop)") {
    asio::io_context io;
    HttpEndpointLimits limits;
    limits.connection_timeout = 1s;
    HttpEndpoint endpoint(io, any_loopback_port, sample_text, limits);
    const auto started = std::chrono::steady_clock::now();
    // No request at all: only the timeout can end this exchange before the 5 s bound.
    const std::string response = exchange(io, endpoint.port(), "");
    const auto took = std::chrono::steady_clock::now() - started;
    CHECK(response.empty());
    CHECK(took >= 900ms);
    CHECK(took < 4s);
}

TEST_CASE("a port in use fails with the address, the failed step and what to do") {
    asio::io_context io;
    asio::ip::tcp::acceptor taken(io, {asio::ip::make_address("127.0.0.1"), 0});
    const config::ListenAddress address{"127.0.0.1", taken.local_endpoint().port()};
    try {
        HttpEndpoint endpoint(io, address, sample_text);
        FAIL("the constructor must throw");
    } catch (const MetricsHttpError& error) {
        const std::string message = error.what();
        CHECK(message.find("cannot listen on " + address.to_string()) != std::string::npos);
        CHECK(message.find("bind failed") != std::string::npos);
        CHECK(message.find("another process listens on port " + std::to_string(address.port)) != std::string::npos);
        CHECK(message.find("metrics_http.listen") != std::string::npos);
    }
}

TEST_CASE("a missing libmicrohttpd fails with the library, dlopen's reason and what to do, before binding") {
    asio::io_context io;
    std::uint16_t port = 0;
    {
        asio::ip::tcp::acceptor probe(io, {asio::ip::make_address("127.0.0.1"), 0});
        port = probe.local_endpoint().port();
    }
    const config::ListenAddress address{"127.0.0.1", port};
    try {
        HttpEndpoint endpoint(io, address, sample_text, {}, "libmicrohttpd-fieldbridge-test-missing.so.12");
        FAIL("the constructor must throw");
    } catch (const MetricsHttpError& error) {
        const std::string message = error.what();
        CHECK(message.find("cannot serve on " + address.to_string()) != std::string::npos);
        CHECK(message.find("cannot load the HTTP library libmicrohttpd-fieldbridge-test-missing.so.12") !=
              std::string::npos);
        CHECK(message.find("cannot open shared object file") != std::string::npos);  // dlerror()
        CHECK(message.find("apt install libmicrohttpd12") != std::string::npos);
        CHECK(message.find("remove the metrics_http section") != std::string::npos);
    }
    // The library is loaded before the port is bound: nothing was left listening.
    asio::ip::tcp::acceptor after(io, {asio::ip::make_address("127.0.0.1"), port});
    CHECK(after.is_open());
}

TEST_CASE("a library without the MHD functions fails naming the missing function") {
    asio::io_context io;
    try {
        HttpEndpoint endpoint(io, any_loopback_port, sample_text, {}, "libc.so.6");
        FAIL("the constructor must throw");
    } catch (const MetricsHttpError& error) {
        const std::string message = error.what();
        CHECK(message.find("libc.so.6 has no MHD_start_daemon") != std::string::npos);
        CHECK(message.find("apt install libmicrohttpd12") != std::string::npos);
    }
}

TEST_CASE("closing the endpoint frees its port at once") {
    asio::io_context io;
    std::uint16_t port = 0;
    {
        HttpEndpoint first(io, any_loopback_port, sample_text);
        port = first.port();
        CHECK(status_line(exchange(io, port, request("GET", "/metrics"))) == "HTTP/1.1 200 OK");
    }
    HttpEndpoint second(io, {"127.0.0.1", port}, sample_text);
    CHECK(status_line(exchange(io, port, request("GET", "/metrics"))) == "HTTP/1.1 200 OK");
}

// Issue 24 item 1: clients at the connection limit that leave must not stop the endpoint
// for good. MHD takes its listening socket out of its epoll set at the limit and puts it
// back only at the start of a later MHD_run(); nothing new becomes ready once the
// clients are gone, so unless the endpoint runs MHD again by itself it never accepts
// (the clients waiting in the backlog, and every later scrape) until a restart.
TEST_CASE("clients that filled the connection limit and left do not stop the next scrape") {
    asio::io_context io;
    HttpEndpointLimits limits;
    limits.max_connections = 2;
    HttpEndpoint endpoint(io, any_loopback_port, sample_text, limits);
    std::vector<asio::ip::tcp::socket> crowd;
    for (int i = 0; i < 4; ++i) crowd.push_back(connect_from(io, endpoint.port(), "127.0.0.1"));
    run_for(io, 300ms);  // two accepted, two waiting in the backlog
    for (auto& socket : crowd) socket.close();
    run_for(io, 300ms);
    CHECK(status_line(exchange(io, endpoint.port(), request("GET", "/metrics"))) == "HTTP/1.1 200 OK");
    CHECK(status_line(exchange(io, endpoint.port(), request("GET", "/metrics"))) == "HTTP/1.1 200 OK");
}

TEST_CASE("a client trickling its request header is cut after the header timeout, however often it sends") {
    asio::io_context io;
    const HttpEndpointLimits limits;  // header 5 s, idle 10 s: only the header deadline can cut it in time
    HttpEndpoint endpoint(io, any_loopback_port, sample_text, limits);
    auto client = connect_from(io, endpoint.port(), "127.0.0.1");
    const auto started = std::chrono::steady_clock::now();
    const std::string header = "GET /metrics HTTP/1.1\r\nX-Slow: " + std::string(200, 'x');
    bool ended = false;
    for (std::size_t i = 0; i < header.size() && !ended; ++i) {
        asio::error_code error;
        asio::write(client, asio::buffer(&header[i], 1), error);
        run_for(io, 250ms);
        ended = error || ended_by_server(client);
        if (std::chrono::steady_clock::now() - started > limits.connection_timeout + 2s) break;
    }
    const auto took = std::chrono::steady_clock::now() - started;
    CHECK(ended);
    CHECK(took >= limits.request_header_timeout - 500ms);
    CHECK(took < limits.request_header_timeout + 2s);
    CHECK(status_line(exchange(io, endpoint.port(), request("GET", "/metrics"))) == "HTTP/1.1 200 OK");
}

TEST_CASE("one client address cannot take every connection") {
    asio::io_context io;
    const HttpEndpointLimits limits;
    HttpEndpoint endpoint(io, any_loopback_port, sample_text, limits);
    std::vector<asio::ip::tcp::socket> hogs;
    for (unsigned i = 0; i < limits.max_connections; ++i) hogs.push_back(connect_from(io, endpoint.port(), "127.0.0.2"));
    run_for(io, 300ms);
    // Those beyond the per-address bound were closed; a scrape from elsewhere is served.
    std::size_t ended = 0;
    for (auto& hog : hogs) ended += ended_by_server(hog) ? 1 : 0;
    CHECK(ended == limits.max_connections - limits.max_connections_per_address);
    CHECK(status_line(exchange(io, endpoint.port(), request("GET", "/metrics"))) == "HTTP/1.1 200 OK");
}

}  // namespace
}  // namespace fieldbridge::northbound::metrics
