#pragma once
/// @file modbus_tcp_server.hpp
/// A loopback Modbus TCP slave for simulated controllers (the Huacheng R6): accepts
/// many clients, frames requests with decode_mbap, hands each PDU to a handler and
/// answers with the same transaction id and unit id. Requests on one connection are
/// answered in order (pipelining is allowed); a malformed MBAP header closes that
/// connection, as the stream cannot be resynchronised.
///
/// Unit id: a real R6 answers whatever unit id it is sent (manual 004 only shows
/// unit 01), so by default every unit is answered. With a unit filter, requests to
/// other units get exception 0x0B (gateway target failed to respond), which makes a
/// wrong unit id visible at once instead of as a timeout.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include <asio/io_context.hpp>
#include <asio/ip/tcp.hpp>
#include <nlohmann/json.hpp>
#include <spdlog/logger.h>

#include "models/bus_device.hpp"
#include "protocol/bytes.hpp"

namespace fieldbridge::sim::runtime {

class ModbusTcpServer {
public:
    /// Request PDU in, response PDU out (empty: no answer).
    using Handler = std::function<protocol::Bytes(protocol::ByteView, Clock::time_point)>;

    struct Counters {
        std::uint64_t connections = 0;
        std::uint64_t requests = 0;
        std::uint64_t replies = 0;
        std::uint64_t exceptions = 0;     ///< replies with the exception flag
        std::uint64_t unit_rejected = 0;  ///< requests to another unit (filter set)
        std::uint64_t malformed = 0;      ///< connections closed for a bad MBAP header
        std::uint64_t unanswered = 0;     ///< the handler gave no reply
    };

    ModbusTcpServer(asio::io_context& io, asio::ip::tcp::endpoint endpoint,
                    std::optional<std::uint8_t> unit, Handler handler,
                    std::shared_ptr<spdlog::logger> log);
    ~ModbusTcpServer();
    ModbusTcpServer(const ModbusTcpServer&) = delete;
    ModbusTcpServer& operator=(const ModbusTcpServer&) = delete;

    /// Binds and listens. Throws SimError (address in use, bad address).
    void open();
    /// Stops accepting and closes every connection. Idempotent.
    void close();

    [[nodiscard]] asio::ip::tcp::endpoint local_endpoint() const;
    [[nodiscard]] nlohmann::json stats() const;

    class Session;  ///< one client connection (defined in the .cpp)

private:
    friend class Session;
    void accept();
    /// Answers one complete request; returns the MBAP reply (empty: none).
    [[nodiscard]] protocol::Bytes answer(std::uint16_t transaction_id, std::uint8_t unit_id,
                                         protocol::ByteView pdu);

    asio::io_context& io_;
    asio::ip::tcp::endpoint endpoint_;
    std::optional<std::uint8_t> unit_;
    Handler handler_;
    std::shared_ptr<spdlog::logger> log_;
    asio::ip::tcp::acceptor acceptor_;
    std::vector<std::weak_ptr<Session>> sessions_;
    std::size_t open_sessions_ = 0;
    Counters counters_;
};

}  // namespace fieldbridge::sim::runtime
