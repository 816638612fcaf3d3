#pragma once
// Test support for the Modbus TCP server: the server's loop on a thread of its own,
// a blocking loopback client with timeouts, and request builders. Every wait is
// bounded.
#include <asio/executor_work_guard.hpp>
#include <asio/io_context.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "config/config.hpp"
#include "northbound/modbus_tcp/server.hpp"
#include "protocol/bytes.hpp"
#include "protocol/mbap_frame.hpp"

namespace fieldbridge::northbound::modbus_tcp::test {

using namespace std::chrono_literals;
using protocol::Bytes;
using protocol::ByteView;

/// Waits bounded by this unless a test says otherwise.
inline constexpr std::chrono::milliseconds wait_limit = 5s;

/// A configuration listening on 127.0.0.1, port chosen by the kernel.
[[nodiscard]] config::ModbusTcpConfig loopback_config();
[[nodiscard]] config::Cidr cidr(const char* text);

/// The server on its own loop thread. Targets are owned here so that they are
/// destroyed on the loop, after the server stopped and before the loop ends.
class Harness {
public:
    using Setup = std::function<void(Harness&)>;
    explicit Harness(config::ModbusTcpConfig config, ServerLimits limits = {}, Setup setup = {});
    ~Harness();
    Harness(const Harness&) = delete;
    Harness& operator=(const Harness&) = delete;

    /// Creates a target owned by the harness and routes @p units to it (before start).
    template <class Target, class... Args>
    Target& add_target(std::vector<std::uint8_t> units, Args&&... args) {
        auto target = std::make_unique<Target>(io, std::forward<Args>(args)...);
        Target& ref = *target;
        for (auto unit : units) server->routes().set(core::UnitId{unit}, ref);
        targets.push_back(std::move(target));
        return ref;
    }

    /// Runs @p f on the loop thread and returns its result; fails the test when the
    /// loop does not run it within wait_limit.
    template <class F>
    auto on_loop(F f) -> decltype(f()) {
        using R = decltype(f());
        auto task = std::make_shared<std::packaged_task<R()>>(std::move(f));
        auto future = task->get_future();
        asio::post(io, [task] { (*task)(); });
        if (future.wait_for(wait_limit) != std::future_status::ready) throw std::runtime_error("loop did not answer");
        return future.get();
    }

    [[nodiscard]] ServerStats stats() { return on_loop([this] { return server->stats(); }); }
    /// Polls the stats until @p done holds; false when wait_limit passes first.
    [[nodiscard]] bool wait_for_stats(const std::function<bool(const ServerStats&)>& done,
                                      std::chrono::milliseconds limit = wait_limit);
    [[nodiscard]] std::vector<std::string> log_lines();

    asio::io_context io;
    std::unique_ptr<ModbusTcpServer> server;
    std::vector<std::unique_ptr<UnitTarget>> targets;
    std::uint16_t port = 0;

private:
    std::optional<asio::executor_work_guard<asio::io_context::executor_type>> work_;
    std::thread thread_;
    std::mutex log_mutex_;
    std::vector<std::string> log_;
};

/// A blocking IPv4 loopback client.
class Client {
public:
    /// @p receive_buffer: SO_RCVBUF before connecting (0: system default).
    explicit Client(std::uint16_t port, int receive_buffer = 0);
    ~Client();
    Client(const Client&) = delete;
    Client& operator=(const Client&) = delete;

    /// Sends everything; false when the connection is gone (or the send stalls past
    /// @p limit).
    bool send(ByteView bytes, std::chrono::milliseconds limit = wait_limit);
    /// The next response frame; nullopt on timeout or when the server closed.
    [[nodiscard]] std::optional<protocol::MbapFrame> receive(std::chrono::milliseconds limit = wait_limit);
    /// True when the server closes the connection within @p limit (data is discarded).
    [[nodiscard]] bool closed_within(std::chrono::milliseconds limit);
    /// Request + its response.
    [[nodiscard]] std::optional<protocol::MbapFrame> ask(ByteView request);

private:
    int fd_ = -1;
    Bytes rx_;
};

/// MBAP request frames.
[[nodiscard]] Bytes read_registers(std::uint16_t transaction, std::uint8_t unit, std::uint16_t address,
                                   std::uint16_t count, std::uint8_t function = 0x03);
[[nodiscard]] Bytes write_register(std::uint16_t transaction, std::uint8_t unit, std::uint16_t address,
                                   std::uint16_t value);
[[nodiscard]] Bytes read_write_registers(std::uint16_t transaction, std::uint8_t unit, std::uint16_t read_address,
                                         std::uint16_t read_count, std::uint16_t write_address,
                                         std::uint16_t write_value);
/// A frame with raw header values (for malformed input).
[[nodiscard]] Bytes raw_frame(std::uint16_t transaction, std::uint16_t protocol_id, std::uint16_t length,
                              ByteView rest);

/// {function | 0x80, code} as a PDU.
[[nodiscard]] Bytes exception_pdu(std::uint8_t function, std::uint8_t code);

}  // namespace fieldbridge::northbound::modbus_tcp::test
