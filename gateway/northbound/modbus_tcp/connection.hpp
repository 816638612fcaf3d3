#pragma once
/// @file connection.hpp
/// One Modbus TCP client connection: frames MBAP requests out of the byte stream,
/// applies the access rules, hands each request to the target of its unit, and
/// writes every response with the transaction ID and unit of its request, in the
/// order the targets answer (pipelining, spec section 4).
///
/// Bounded: at most ServerLimits::max_outstanding requests with targets (then the
/// socket is not read until one is answered) and ServerLimits::max_output_bytes of
/// unsent responses (then the connection is closed). A malformed MBAP header ends
/// the connection: a TCP stream cannot be resynchronised. Reading stops there; the
/// requests accepted before it are still answered, then the connection closes
/// (a client that retries must not have its write executed twice).
///
/// Deadlines: a frame must be complete within frame_timeout of its first byte
/// (a client trickling bytes cannot hold a connection); the idle timeout counts
/// from the last complete request or sent answer, not from any byte.
///
/// Loop thread only. Owned by the server through shared_ptr while open; pending
/// socket operations and the answer handlers given to targets keep it alive after
/// the close (a closed connection only counts late answers and drops them).
#include <asio/ip/tcp.hpp>
#include <asio/steady_timer.hpp>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/modbus_ids.hpp"
#include "northbound/modbus_tcp/connection_context.hpp"
#include "northbound/unit_target.hpp"
#include "protocol/bytes.hpp"
#include "protocol/gateway_exceptions.hpp"

namespace fieldbridge::northbound::modbus_tcp {

enum class CloseReason : std::uint8_t {
    peer,             ///< the client closed or reset the connection
    io_error,         ///< read or write failed otherwise
    malformed,        ///< bad MBAP header (after the requests before it were answered)
    frame_timeout,    ///< a frame not complete within frame_timeout of its first byte
    output_overflow,  ///< the client does not read its responses
    idle,             ///< no complete request and no answer sent for idle_timeout
    not_allowed,      ///< a reload removed the client from the allow-list
    server_stop,
};

[[nodiscard]] const char* to_string(CloseReason reason) noexcept;

class Connection : public std::enable_shared_from_this<Connection> {
public:
    Connection(std::shared_ptr<ConnectionContext> context, asio::ip::tcp::socket socket, ClientRef client,
               std::string peer);
    ~Connection();
    Connection(const Connection&) = delete;
    Connection& operator=(const Connection&) = delete;

    /// Starts reading and the idle timer.
    void start();
    /// Closes the socket, tells every routed target (client_closed) when this
    /// connection sent it anything, and reports to the server. Idempotent.
    void close(CloseReason reason);
    /// The idle timeout may have changed (reload): re-arm the timer with it.
    void restart_idle_timer();

    [[nodiscard]] const ClientRef& client() const noexcept { return client_; }
    [[nodiscard]] const std::string& peer() const noexcept { return peer_; }
    [[nodiscard]] bool closed() const noexcept { return closed_; }
    [[nodiscard]] std::size_t outstanding() const noexcept { return outstanding_; }

private:
    /// A request with a target: what its answer needs. `generation` makes a second
    /// or stale call of an answer handler harmless.
    struct Slot {
        std::uint32_t generation = 0;
        std::uint16_t transaction_id = 0;
        core::UnitId unit;
        core::FunctionCode function;
        bool busy = false;
    };

    void read();
    void on_read(const asio::error_code& error, std::size_t count);
    /// Frames and dispatches buffered requests while slots are free.
    void process();
    void dispatch(std::uint16_t transaction_id, core::UnitId unit, protocol::ByteView pdu);
    void complete(std::uint16_t slot, std::uint32_t generation, protocol::Bytes response_pdu);
    void respond(std::uint16_t transaction_id, core::UnitId unit, protocol::ByteView pdu);
    void respond_exception(std::uint16_t transaction_id, core::UnitId unit, core::FunctionCode function,
                           protocol::GatewayRefusal refusal);
    void write();
    void on_write(const asio::error_code& error);
    /// Resumes reading after a slot freed (posted: never inside a target's call).
    void schedule_resume();
    /// Closes later from the loop (never inside a target's call of its handler).
    void schedule_close(CloseReason reason);
    void arm_idle_timer();
    void on_idle_timer(const asio::error_code& error);
    /// Watches the partial frame at the front of the buffer (lazy: one wait per frame).
    void arm_frame_timer();
    void on_frame_timer(const asio::error_code& error);
    [[nodiscard]] bool partial_frame_buffered() const noexcept;
    /// A malformed header: stop taking requests, answer those accepted, then close.
    void start_draining();
    /// Closes a draining connection once nothing is owed to or waiting for the client.
    void finish_draining();
    void notify_targets();
    void release_read_buffer();
    [[nodiscard]] std::size_t buffered() const noexcept { return rx_end_ - rx_begin_; }

    std::shared_ptr<ConnectionContext> context_;
    asio::ip::tcp::socket socket_;
    asio::steady_timer idle_timer_;
    asio::steady_timer frame_timer_;
    ClientRef client_;
    std::string peer_;

    std::vector<std::uint8_t> rx_;
    std::size_t rx_begin_ = 0;
    std::size_t rx_end_ = 0;
    bool reading_ = false;
    bool resume_scheduled_ = false;

    std::vector<Slot> slots_;
    std::vector<std::uint16_t> free_slots_;
    std::size_t outstanding_ = 0;
    bool forwarded_ = false;  ///< some target saw a request of this connection

    protocol::Bytes out_pending_;  ///< responses queued while a write is in flight
    protocol::Bytes out_sending_;  ///< the write in flight
    bool writing_ = false;
    bool close_scheduled_ = false;

    std::chrono::steady_clock::time_point last_activity_;  ///< last complete request or sent answer
    bool idle_waiting_ = false;
    std::chrono::steady_clock::time_point frame_started_;  ///< first byte of the frame at rx_begin_
    bool frame_waiting_ = false;
    bool draining_ = false;  ///< a malformed header was received: no more requests
    bool closed_ = false;
};

}  // namespace fieldbridge::northbound::modbus_tcp
