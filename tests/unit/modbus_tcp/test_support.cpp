#include "test_support.hpp"

#include <arpa/inet.h>
#include <asio/post.hpp>
#include <cerrno>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <stdexcept>
#include <sys/socket.h>
#include <unistd.h>

#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::northbound::modbus_tcp::test {
namespace {

using Clock = std::chrono::steady_clock;

[[nodiscard]] int remaining_ms(Clock::time_point deadline) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    return left < 0 ? 0 : static_cast<int>(left);
}

}  // namespace

config::ModbusTcpConfig loopback_config() {
    config::ModbusTcpConfig config;
    config.listen = {config::ListenAddress{"127.0.0.1", 0}};
    return config;
}

config::Cidr cidr(const char* text) {
    auto parsed = config::parse_cidr(text);
    if (!parsed) throw std::invalid_argument(parsed.error);
    return *parsed.value;
}

Harness::Harness(config::ModbusTcpConfig config, ServerLimits limits, Setup setup) {
    engine::LogSink sink;
    sink.min_level = engine::LogLevel::debug;
    sink.write = [this](engine::LogLevel, std::string_view line) {
        const std::lock_guard lock(log_mutex_);
        log_.emplace_back(line);
    };
    server = std::make_unique<ModbusTcpServer>(io, std::make_shared<const config::ModbusTcpConfig>(std::move(config)),
                                               std::move(sink), limits);
    if (setup) setup(*this);
    server->start();
    port = server->port();
    work_.emplace(io.get_executor());
    thread_ = std::thread([this] { io.run(); });
}

Harness::~Harness() {
    try {
        on_loop([this] {
            server->stop();
            server.reset();
            targets.clear();
            return 0;
        });
    } catch (...) {
        // The loop is stuck: nothing sensible is left to clean up but the thread.
    }
    work_.reset();
    io.stop();
    thread_.join();
}

bool Harness::wait_for_stats(const std::function<bool(const ServerStats&)>& done, std::chrono::milliseconds limit) {
    const auto deadline = Clock::now() + limit;
    while (Clock::now() < deadline) {
        if (done(stats())) return true;
        std::this_thread::sleep_for(5ms);
    }
    return done(stats());
}

std::vector<std::string> Harness::log_lines() {
    const std::lock_guard lock(log_mutex_);
    return log_;
}

Client::Client(std::uint16_t port, int receive_buffer) {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd_ < 0) throw std::runtime_error("socket() failed");
    if (receive_buffer > 0) ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof receive_buffer);
    const int one = 1;
    ::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(port);
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
        ::close(fd_);
        throw std::runtime_error("connect to 127.0.0.1:" + std::to_string(port) + " failed");
    }
}

Client::~Client() {
    if (fd_ >= 0) ::close(fd_);
}

bool Client::send(ByteView bytes, std::chrono::milliseconds limit) {
    const auto deadline = Clock::now() + limit;
    std::size_t sent = 0;
    while (sent < bytes.size()) {
        pollfd pfd{fd_, POLLOUT, 0};
        if (::poll(&pfd, 1, remaining_ms(deadline)) <= 0) return false;
        const auto n = ::send(fd_, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL | MSG_DONTWAIT);
        if (n < 0) {
            if (errno == EAGAIN || errno == EINTR) continue;
            return false;
        }
        sent += static_cast<std::size_t>(n);
    }
    return true;
}

std::optional<protocol::MbapFrame> Client::receive(std::chrono::milliseconds limit) {
    const auto deadline = Clock::now() + limit;
    for (;;) {
        const auto frame = protocol::decode_mbap(rx_);
        if (frame.complete()) {
            rx_.erase(rx_.begin(), rx_.begin() + static_cast<std::ptrdiff_t>(frame.consumed));
            return frame.value;
        }
        if (frame.malformed()) throw std::runtime_error("the server sent a malformed MBAP frame");
        pollfd pfd{fd_, POLLIN, 0};
        if (::poll(&pfd, 1, remaining_ms(deadline)) <= 0) return std::nullopt;
        std::uint8_t buffer[4096];
        const auto n = ::recv(fd_, buffer, sizeof buffer, MSG_DONTWAIT);
        if (n == 0) return std::nullopt;
        if (n < 0) {
            if (errno == EAGAIN || errno == EINTR) continue;
            return std::nullopt;
        }
        rx_.insert(rx_.end(), buffer, buffer + n);
    }
}

bool Client::closed_within(std::chrono::milliseconds limit) {
    const auto deadline = Clock::now() + limit;
    for (;;) {
        pollfd pfd{fd_, POLLIN, 0};
        if (::poll(&pfd, 1, remaining_ms(deadline)) <= 0) return false;
        std::uint8_t buffer[4096];
        const auto n = ::recv(fd_, buffer, sizeof buffer, MSG_DONTWAIT);
        if (n == 0) return true;
        if (n < 0 && errno != EAGAIN && errno != EINTR) return true;  // reset
    }
}

std::optional<protocol::MbapFrame> Client::ask(ByteView request) {
    if (!send(request)) return std::nullopt;
    return receive();
}

Bytes read_registers(std::uint16_t transaction, std::uint8_t unit, std::uint16_t address, std::uint16_t count,
                     std::uint8_t function) {
    return protocol::encode_mbap(transaction, core::UnitId{unit},
                                 protocol::encode_request(protocol::ReadRegistersRequest{function, address, count}));
}

Bytes write_register(std::uint16_t transaction, std::uint8_t unit, std::uint16_t address, std::uint16_t value) {
    return protocol::encode_mbap(transaction, core::UnitId{unit},
                                 protocol::encode_request(protocol::WriteSingleRegisterRequest{address, value}));
}

Bytes read_write_registers(std::uint16_t transaction, std::uint8_t unit, std::uint16_t read_address,
                           std::uint16_t read_count, std::uint16_t write_address, std::uint16_t write_value) {
    return protocol::encode_mbap(
        transaction, core::UnitId{unit},
        protocol::encode_request(protocol::ReadWriteRegistersRequest{read_address, read_count, write_address, {write_value}}));
}

Bytes raw_frame(std::uint16_t transaction, std::uint16_t protocol_id, std::uint16_t length, ByteView rest) {
    Bytes out;
    protocol::put_u16_be(out, transaction);
    protocol::put_u16_be(out, protocol_id);
    protocol::put_u16_be(out, length);
    out.insert(out.end(), rest.begin(), rest.end());
    return out;
}

Bytes exception_pdu(std::uint8_t function, std::uint8_t code) {
    return Bytes{static_cast<std::uint8_t>(function | 0x80), code};
}

}  // namespace fieldbridge::northbound::modbus_tcp::test
