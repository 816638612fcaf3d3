// Benchmark of the Modbus TCP server alone (spec section 9, "cache-served reads"):
// N loopback clients, each with one FC03 request outstanding at a time (like a PLC
// polling), against a target that answers at once from memory, as a device adapter
// does when the register image is fresh. Prints requests/s and latency percentiles.
//
//   fb_bench_modbus_tcp_server [clients=32] [seconds=5] [registers=2]
//
// The server runs on its own thread (the daemon's loop); the load generator on
// another, with poll() over non-blocking sockets. Not a test: it asserts nothing.
#include <poll.h>
#include <sys/socket.h>

#include <algorithm>
#include <asio/executor_work_guard.hpp>
#include <asio/io_context.hpp>
#include <asio/post.hpp>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "loopback_port.hpp"
#include "northbound/modbus_tcp/server.hpp"
#include "protocol/mbap_frame.hpp"
#include "protocol/modbus_pdu.hpp"

namespace {

using namespace fieldbridge;
using Clock = std::chrono::steady_clock;

/// Answers every request with the same prepared response, posted like a real adapter.
class CachedTarget final : public northbound::UnitTarget {
public:
    CachedTarget(asio::io_context& io, std::uint16_t registers) : io_(io) {
        response_ = protocol::encode_response(
            protocol::ReadRegistersResponse{0x03, std::vector<std::uint16_t>(registers, 0x1234)});
    }
    void handle(core::UnitId, const northbound::RequestPdu&, const northbound::ClientRef&,
                northbound::PduHandler done) override {
        asio::post(io_, [this, done = std::move(done)] { done(response_); });
    }

private:
    asio::io_context& io_;
    protocol::Bytes response_;
};

struct BenchClient {
    test_support::UniqueFd fd;
    protocol::Bytes request;
    protocol::Bytes rx;
    std::size_t expected = 0;
    Clock::time_point sent;
};

}  // namespace

int main(int argc, char** argv) {
    const std::size_t clients = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 32;
    const double seconds = argc > 2 ? std::strtod(argv[2], nullptr) : 5.0;
    const auto registers = static_cast<std::uint16_t>(argc > 3 ? std::strtoul(argv[3], nullptr, 10) : 2);

    asio::io_context io;
    config::ModbusTcpConfig config;
    config.listen = {config::ListenAddress{"127.0.0.1", 0}};
    config.max_connections = clients + 1;
    config.max_connections_per_client = clients + 1;  // every client is 127.0.0.1
    northbound::modbus_tcp::ModbusTcpServer server(io, std::make_shared<const config::ModbusTcpConfig>(config), {});
    CachedTarget target(io, registers);
    server.routes().set(core::UnitId{1}, target);
    server.start();
    const auto port = server.port();
    auto work = asio::make_work_guard(io);
    std::thread loop([&io] { io.run(); });

    std::vector<BenchClient> pool(clients);
    std::vector<pollfd> fds(clients);
    const std::size_t response_size = protocol::mbap_header_size + 2 + 2U * registers;
    for (std::size_t i = 0; i < clients; ++i) {
        pool[i].fd = bench::connect_loopback(port);
        pool[i].request = protocol::encode_mbap(
            static_cast<std::uint16_t>(i), core::UnitId{1},
            protocol::encode_request(protocol::ReadRegistersRequest{0x03, 0x0300, registers}));
        pool[i].expected = response_size;
        fds[i] = pollfd{pool[i].fd.get(), POLLIN, 0};
    }
    std::vector<double> latencies_us;
    latencies_us.reserve(static_cast<std::size_t>(seconds * 200000));
    const auto send = [](BenchClient& c) {
        c.sent = Clock::now();
        if (::send(c.fd.get(), c.request.data(), c.request.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(c.request.size())) {
            throw std::runtime_error("send failed");
        }
    };
    for (auto& c : pool) send(c);
    const auto start = Clock::now();
    const auto end = start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
    std::uint8_t buffer[4096];
    while (Clock::now() < end) {
        if (::poll(fds.data(), fds.size(), 1000) <= 0) throw std::runtime_error("no answer within 1 s");
        for (std::size_t i = 0; i < clients; ++i) {
            if ((fds[i].revents & POLLIN) == 0) continue;
            BenchClient& c = pool[i];
            const auto n = ::recv(c.fd.get(), buffer, sizeof buffer, MSG_DONTWAIT);
            if (n <= 0) throw std::runtime_error("connection lost");
            c.rx.insert(c.rx.end(), buffer, buffer + n);
            while (c.rx.size() >= c.expected) {
                c.rx.erase(c.rx.begin(), c.rx.begin() + static_cast<std::ptrdiff_t>(c.expected));
                latencies_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - c.sent).count());
                send(c);
            }
        }
    }
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    asio::post(io, [&] { server.stop(); });
    work.reset();
    loop.join();

    std::sort(latencies_us.begin(), latencies_us.end());
    const auto percentile = [&](double p) {
        if (latencies_us.empty()) return 0.0;
        return latencies_us[std::min(latencies_us.size() - 1, static_cast<std::size_t>(p * static_cast<double>(latencies_us.size())))];
    };
    std::printf("clients %zu, %.1f s: %zu reads, %.0f reads/s; latency p50 %.0f us, p99 %.0f us, max %.0f us\n",
                clients, elapsed, latencies_us.size(), static_cast<double>(latencies_us.size()) / elapsed,
                percentile(0.50), percentile(0.99), latencies_us.empty() ? 0.0 : latencies_us.back());
    return 0;
}
