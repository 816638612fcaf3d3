#pragma once
// Test support for the R6 pass-through: an in-process scriptable Modbus TCP server,
// bounded loop running, answer capture. The fieldbridge-sim R6 child process:
// tests/support/sim_process.hpp.
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <asio/io_context.hpp>
#include <asio/ip/tcp.hpp>

#include "config/config.hpp"
#include "engine/line_log.hpp"
#include "northbound/unit_target.hpp"
#include "protocol/bytes.hpp"
#include "run_until.hpp"

namespace fbtest {

using fieldbridge::protocol::Bytes;

/// A loopback TCP port nobody listens on right now.
[[nodiscard]] std::uint16_t free_port();

using fieldbridge::test_support::run_for;
using fieldbridge::test_support::run_until;

/// An upstream config for 127.0.0.1:@p port with gateway unit 10 -> upstream unit 1,
/// short timeouts for tests.
[[nodiscard]] fieldbridge::config::UpstreamConfig config_for(std::uint16_t port);

/// Log lines kept for assertions and printed on failure.
struct CapturedLog {
    std::shared_ptr<std::vector<std::string>> lines = std::make_shared<std::vector<std::string>>();
    [[nodiscard]] fieldbridge::engine::LogSink sink(fieldbridge::engine::LogLevel min =
                                                        fieldbridge::engine::LogLevel::info) const;
    [[nodiscard]] bool contains(const std::string& text) const;
};

/// One answer slot per request.
struct Answer {
    bool done = false;
    Bytes pdu;
    int calls = 0;
};
[[nodiscard]] fieldbridge::northbound::PduHandler capture(std::shared_ptr<Answer> answer);

/// A client reference with only an id (no connection behind it).
[[nodiscard]] inline fieldbridge::northbound::ClientRef client(std::uint64_t id) {
    return fieldbridge::northbound::ClientRef{id, {}};
}

/// R6 (seed 004): read the mode register 0x0889, one register.
inline const Bytes mode_read{0x03, 0x08, 0x89, 0x00, 0x01};

[[nodiscard]] Bytes hex(const std::string& text);
[[nodiscard]] std::string to_hex(const Bytes& bytes);

/// A scriptable upstream on the test's io_context: every complete MBAP request is
/// handed to `on_request`, which answers through `send` (or not at all).
class FakeUpstream {
public:
    struct Request {
        std::uint16_t transaction_id = 0;
        std::uint8_t unit = 0;
        Bytes pdu;
    };
    using OnRequest = std::function<void(FakeUpstream&, const Request&)>;

    FakeUpstream(asio::io_context& io, OnRequest on_request);
    ~FakeUpstream();
    [[nodiscard]] std::uint16_t port() const;
    /// Sends a reply frame on the current connection.
    void send(std::uint16_t transaction_id, std::uint8_t unit, const Bytes& pdu);
    [[nodiscard]] const std::vector<Request>& requests() const noexcept { return requests_; }
    [[nodiscard]] int connections() const noexcept { return connections_; }

private:
    void accept();
    void read();

    asio::ip::tcp::acceptor acceptor_;
    std::shared_ptr<asio::ip::tcp::socket> socket_;
    std::shared_ptr<std::array<std::uint8_t, 1024>> chunk_;
    Bytes received_;
    OnRequest on_request_;
    std::vector<Request> requests_;
    int connections_ = 0;
    std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace fbtest
