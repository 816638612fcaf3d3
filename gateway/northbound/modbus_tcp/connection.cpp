// One Modbus TCP client connection. MBAP layout: Modbus Messaging on TCP/IP
// Implementation Guide V1.0b section 3.1.3 (protocol/mbap_frame.hpp frames it).
#include "northbound/modbus_tcp/connection.hpp"
#include "northbound/modbus_tcp/server_log.hpp"

#include <algorithm>
#include <asio/post.hpp>
#include <asio/write.hpp>
#include <cstring>
#include <exception>
#include <fmt/format.h>
#include <span>
#include <utility>

#include "northbound/modbus_tcp/access_control.hpp"
#include "protocol/mbap_frame.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::northbound::modbus_tcp {
namespace {

using engine::LogLevel;
using Clock = std::chrono::steady_clock;

/// Appends one MBAP frame (header + PDU) to @p out without a temporary buffer:
/// responses of one connection are gathered into one write.
void append_mbap(protocol::Bytes& out, std::uint16_t transaction_id, core::UnitId unit, protocol::ByteView pdu) {
    protocol::put_u16_be(out, transaction_id);
    protocol::put_u16_be(out, 0);  // protocol identifier: Modbus
    protocol::put_u16_be(out, static_cast<std::uint16_t>(pdu.size() + 1));
    out.push_back(unit.value);
    out.insert(out.end(), pdu.begin(), pdu.end());
}

[[nodiscard]] std::uint64_t& close_counter(ServerStats& stats, CloseReason reason) noexcept {
    switch (reason) {
        case CloseReason::peer: return stats.closed_by_peer;
        case CloseReason::malformed: return stats.closed_malformed;
        case CloseReason::frame_timeout: return stats.closed_frame_timeout;
        case CloseReason::output_overflow: return stats.closed_output_overflow;
        case CloseReason::idle: return stats.closed_idle;
        case CloseReason::io_error:
        case CloseReason::not_allowed:
        case CloseReason::server_stop: break;
    }
    return stats.closed_io_error;
}

}  // namespace

const char* to_string(CloseReason reason) noexcept {
    switch (reason) {
        case CloseReason::peer: return "closed by the client";
        case CloseReason::io_error: return "socket error";
        case CloseReason::malformed: return "malformed MBAP frame";
        case CloseReason::frame_timeout: return "frame not completed within modbus_tcp.frame_timeout";
        case CloseReason::output_overflow: return "client does not read its responses";
        case CloseReason::idle: return "idle timeout";
        case CloseReason::not_allowed: return "client no longer in the allow-list";
        case CloseReason::server_stop: return "server stopping";
    }
    return "?";
}

Connection::Connection(std::shared_ptr<ConnectionContext> context, asio::ip::tcp::socket socket, ClientRef client,
                       std::string peer)
    : context_(std::move(context)),
      socket_(std::move(socket)),
      idle_timer_(socket_.get_executor()),
      frame_timer_(socket_.get_executor()),
      client_(client),
      peer_(std::move(peer)),
      rx_(context_->limits.read_buffer_bytes),
      slots_(context_->limits.max_outstanding) {
    free_slots_.reserve(slots_.size());
    for (std::size_t i = slots_.size(); i > 0; --i) free_slots_.push_back(static_cast<std::uint16_t>(i - 1));
}

Connection::~Connection() = default;

void Connection::start() {
    last_activity_ = Clock::now();
    // write() tries a send at once: it must never block on a client that stopped
    // reading. (asio's asynchronous operations work the same either way.)
    asio::error_code error;
    socket_.non_blocking(true, error);
    if (error) {
        log(context_->log, LogLevel::info, "Modbus TCP: client {}: cannot make the socket non-blocking: {}", peer_,
            error.message());
        close(CloseReason::io_error);
        return;
    }
    arm_idle_timer();
    read();
}

void Connection::read() {
    if (closed_ || reading_) return;
    // A draining connection reads only to discard (data left unread would make the
    // close a reset, which may destroy the answers still in flight to the client).
    if (!draining_ && (outstanding_ >= slots_.size() || rx_end_ == rx_.size())) return;
    reading_ = true;
    socket_.async_read_some(asio::buffer(rx_.data() + rx_end_, rx_.size() - rx_end_),
                            [self = shared_from_this()](const asio::error_code& error, std::size_t count) {
                                self->on_read(error, count);
                            });
}

void Connection::on_read(const asio::error_code& error, std::size_t count) {
    reading_ = false;
    if (closed_) {
        release_read_buffer();
        return;
    }
    if (error) {
        const bool by_peer = error == asio::error::eof || error == asio::error::connection_reset;
        if (!by_peer) {
            log(context_->log, LogLevel::info, "Modbus TCP: client {}: read failed: {}", peer_, error.message());
        }
        close(by_peer ? CloseReason::peer : CloseReason::io_error);
        return;
    }
    if (draining_) {
        rx_begin_ = rx_end_ = 0;
        read();
        return;
    }
    if (buffered() == 0 && count > 0) frame_started_ = Clock::now();
    rx_end_ += count;
    process();
    read();
}

void Connection::process() {
    while (!closed_ && !draining_ && outstanding_ < slots_.size() && buffered() > 0) {
        const protocol::ByteView stream(rx_.data() + rx_begin_, buffered());
        const auto frame = protocol::decode_mbap(stream);
        if (frame.need_more()) break;
        if (frame.malformed()) {
            log(context_->log, LogLevel::warning,
                "Modbus TCP: client {} sent a malformed MBAP header ({}); answering the {} request(s) accepted "
                "before it, then closing its connection",
                peer_, protocol::to_string(frame.error), outstanding_);
            start_draining();
            return;
        }
        rx_begin_ += frame.consumed;
        // The next frame's first byte arrived at the latest now.
        last_activity_ = frame_started_ = Clock::now();
        dispatch(frame.value.transaction_id, frame.value.unit_id, frame.value.pdu);
    }
    if (closed_ || draining_) return;
    // Keep the partial frame at the front so the buffer always has room for a whole one.
    if (rx_begin_ == rx_end_) {
        rx_begin_ = rx_end_ = 0;
    } else if (rx_begin_ > 0 && rx_end_ + protocol::mbap_header_size + protocol::mbap_max_length > rx_.size()) {
        std::memmove(rx_.data(), rx_.data() + rx_begin_, buffered());
        rx_end_ -= rx_begin_;
        rx_begin_ = 0;
    }
    arm_frame_timer();
}

bool Connection::partial_frame_buffered() const noexcept {
    return buffered() > 0 && protocol::decode_mbap(protocol::ByteView(rx_.data() + rx_begin_, buffered())).need_more();
}

void Connection::arm_frame_timer() {
    if (closed_ || draining_ || frame_waiting_ || !partial_frame_buffered()) return;
    frame_timer_.expires_at(frame_started_ + context_->config->frame_timeout);
    frame_waiting_ = true;
    frame_timer_.async_wait([self = shared_from_this()](const asio::error_code& error) { self->on_frame_timer(error); });
}

void Connection::on_frame_timer(const asio::error_code& /*error*/) {
    frame_waiting_ = false;
    if (closed_ || draining_ || !partial_frame_buffered()) return;
    const auto timeout = context_->config->frame_timeout;
    if (Clock::now() >= frame_started_ + timeout) {
        log(context_->log, LogLevel::warning,
            "Modbus TCP: client {} did not complete a frame within {} ms of its first byte ({} bytes received); "
            "closing its connection (modbus_tcp.frame_timeout)",
            peer_, timeout.count(), buffered());
        close(CloseReason::frame_timeout);
        return;
    }
    arm_frame_timer();  // a later frame is the one waiting now
}

void Connection::start_draining() {
    draining_ = true;
    rx_begin_ = rx_end_ = 0;
    frame_timer_.cancel();
    finish_draining();
}

void Connection::finish_draining() {
    if (draining_ && outstanding_ == 0 && !writing_ && out_pending_.empty()) schedule_close(CloseReason::malformed);
}

void Connection::dispatch(std::uint16_t transaction_id, core::UnitId unit, protocol::ByteView pdu) {
    ConnectionContext& context = *context_;
    ++context.stats.requests;
    // Decoded once: the rules, the target and the device's profile read this.
    const RequestPdu request = RequestPdu::decode(pdu);
    const RequestScope scope = request_scope(request);
    const core::FunctionCode function = scope.function;
    UnitTarget* target = context.routes.find(unit);
    // A broadcast unit answers for the units of its line: a request it may carry
    // must be allowed for each of them too (docs/modbus-tcp.md, "Broadcast units").
    const auto denied = [&] {
        if (!request_allowed(*context.config, client_.address, unit, scope)) return true;
        if (target == nullptr) return false;
        const std::span<const core::UnitId> also = target->ruled_as();
        return std::any_of(also.begin(), also.end(), [&](core::UnitId covered) {
            return !request_allowed(*context.config, client_.address, covered, scope);
        });
    };
    if (denied()) {
        ++context.stats.denied;
        log(context.log, LogLevel::debug, "Modbus TCP: client {}: unit {} function {} denied by an access rule",
            peer_, unit.value, function.value);
        respond_exception(transaction_id, unit, function, protocol::GatewayRefusal::denied);
        return;
    }
    if (target == nullptr) {
        ++context.stats.unknown_unit;
        log(context.log, LogLevel::debug, "Modbus TCP: client {}: unit {} has no route", peer_, unit.value);
        respond_exception(transaction_id, unit, function, protocol::GatewayRefusal::path_down);
        return;
    }
    if (!core::is_function_code(function)) {
        // Function byte 0 or >= 0x80 (or an empty PDU): answered here, the same way for
        // every kind of target.
        respond_exception(transaction_id, unit, function, protocol::GatewayRefusal::not_a_function);
        return;
    }
    const std::uint16_t index = free_slots_.back();
    free_slots_.pop_back();
    Slot& slot = slots_[index];
    slot.busy = true;
    slot.transaction_id = transaction_id;
    slot.unit = unit;
    slot.function = function;
    const std::uint32_t generation = slot.generation;
    ++outstanding_;
    forwarded_ = true;
    try {
        // The handler keeps this connection (not its socket: close() releases that)
        // so that an answer arriving after the close is counted and dropped here.
        target->handle(unit, request, client_,
                       [self = shared_from_this(), index, generation](protocol::Bytes response) {
                           self->complete(index, generation, std::move(response));
                       });
    } catch (const std::exception& e) {
        ++context.stats.target_failures;
        log(context.log, LogLevel::error, "Modbus TCP: the target of unit {} failed on a request of {}: {}", unit.value,
            peer_, e.what());
        if (slot.busy && slot.generation == generation) {
            complete(index, generation,
                     protocol::exception_pdu(function, protocol::GatewayRefusal::gateway_failure));
        }
    }
}

void Connection::complete(std::uint16_t index, std::uint32_t generation, protocol::Bytes response_pdu) {
    Slot& slot = slots_[index];
    if (!slot.busy || slot.generation != generation) return;  // answered twice: the first answer stands
    if (closed_) {
        ++context_->stats.late_responses;
        slot.busy = false;
        ++slot.generation;
        return;
    }
    slot.busy = false;
    ++slot.generation;
    free_slots_.push_back(index);
    const bool was_full = outstanding_ == slots_.size();
    --outstanding_;
    if (response_pdu.empty() || response_pdu.size() > protocol::max_pdu_size) {
        ++context_->stats.target_failures;
        log(context_->log, LogLevel::error,
            "Modbus TCP: the target of unit {} answered a PDU of {} bytes (1..{} allowed); sending exception 0x04",
            slot.unit.value, response_pdu.size(), protocol::max_pdu_size);
        respond_exception(slot.transaction_id, slot.unit, slot.function, protocol::GatewayRefusal::gateway_failure);
    } else {
        respond(slot.transaction_id, slot.unit, response_pdu);
    }
    if (was_full) schedule_resume();
    finish_draining();
}

void Connection::respond_exception(std::uint16_t transaction_id, core::UnitId unit, core::FunctionCode function,
                                   protocol::GatewayRefusal refusal) {
    respond(transaction_id, unit, protocol::exception_pdu(function, refusal));
}

void Connection::respond(std::uint16_t transaction_id, core::UnitId unit, protocol::ByteView pdu) {
    ServerStats& stats = context_->stats;
    ++stats.responses;
    if (pdu.size() >= 2 && (pdu[0] & protocol::fc::exception_flag) != 0) ++stats.exceptions_by_code[pdu[1]];
    if (close_scheduled_) return;
    append_mbap(out_pending_, transaction_id, unit, pdu);
    if (out_pending_.size() + out_sending_.size() > context_->limits.max_output_bytes) {
        log(context_->log, LogLevel::warning,
            "Modbus TCP: client {} does not read its responses ({} bytes waiting); closing its connection", peer_,
            out_pending_.size() + out_sending_.size());
        schedule_close(CloseReason::output_overflow);
        return;
    }
    write();
}

void Connection::write() {
    if (writing_ || closed_ || out_pending_.empty()) return;
    // Answers are small and the socket's buffer is almost always free: sent at once,
    // they cost no pass through the loop for an asynchronous write's completion
    // (docs/performance.md). What does not fit (a client that does not read), and a
    // failed send, go the asynchronous way; on_write reports the failure.
    asio::error_code send_error;
    const std::size_t sent = socket_.write_some(asio::buffer(out_pending_), send_error);
    if (!send_error && sent == out_pending_.size()) {
        out_pending_.clear();
        last_activity_ = Clock::now();
        return;
    }
    if (!send_error) out_pending_.erase(out_pending_.begin(), out_pending_.begin() + static_cast<std::ptrdiff_t>(sent));
    writing_ = true;
    out_sending_.swap(out_pending_);
    asio::async_write(socket_, asio::buffer(out_sending_),
                      [self = shared_from_this()](const asio::error_code& error, std::size_t /*sent*/) {
                          self->on_write(error);
                      });
}

void Connection::on_write(const asio::error_code& error) {
    writing_ = false;
    if (closed_) {
        out_sending_ = protocol::Bytes{};
        return;
    }
    if (error) {
        const bool by_peer = error == asio::error::broken_pipe || error == asio::error::connection_reset;
        if (!by_peer) {
            log(context_->log, LogLevel::info, "Modbus TCP: client {}: write failed: {}", peer_, error.message());
        }
        close(by_peer ? CloseReason::peer : CloseReason::io_error);
        return;
    }
    out_sending_.clear();  // keeps its capacity for the next batch
    last_activity_ = Clock::now();
    write();
    finish_draining();
}

void Connection::schedule_resume() {
    if (resume_scheduled_ || closed_) return;
    resume_scheduled_ = true;
    asio::post(socket_.get_executor(), [self = shared_from_this()] {
        self->resume_scheduled_ = false;
        if (self->closed_ || self->draining_) return;
        self->process();
        self->read();
    });
}

void Connection::schedule_close(CloseReason reason) {
    if (close_scheduled_ || closed_) return;
    close_scheduled_ = true;
    asio::post(socket_.get_executor(), [self = shared_from_this(), reason] { self->close(reason); });
}

void Connection::arm_idle_timer() {
    const auto timeout = context_->config->idle_timeout;
    if (closed_ || idle_waiting_ || timeout.count() <= 0) return;
    // The timer is not moved on every request: when it fires it looks at the last
    // activity and waits again for the rest of the timeout.
    const auto now = Clock::now();
    const auto deadline = outstanding_ > 0 ? now + timeout : std::max(last_activity_ + timeout, now);
    idle_timer_.expires_at(deadline);
    idle_waiting_ = true;
    idle_timer_.async_wait([self = shared_from_this()](const asio::error_code& error) { self->on_idle_timer(error); });
}

void Connection::restart_idle_timer() {
    if (closed_) return;
    if (idle_waiting_) {
        idle_timer_.cancel();  // on_idle_timer re-arms with the new timeout
    } else {
        arm_idle_timer();
    }
}

void Connection::on_idle_timer(const asio::error_code& /*error*/) {
    idle_waiting_ = false;
    if (closed_) return;
    const auto timeout = context_->config->idle_timeout;
    if (timeout.count() <= 0) return;
    // A client waiting for an answer is not idle: the target owes it one.
    if (outstanding_ == 0 && Clock::now() >= last_activity_ + timeout) {
        if (buffered() > 0) {
            log(context_->log, LogLevel::warning,
                "Modbus TCP: client {} left a frame incomplete ({} bytes) for {} ms; closing its connection", peer_,
                buffered(), timeout.count());
            close(CloseReason::malformed);
        } else {
            log(context_->log, LogLevel::info, "Modbus TCP: client {} idle for {} ms; closing its connection", peer_,
                timeout.count());
            close(CloseReason::idle);
        }
        return;
    }
    arm_idle_timer();
}

void Connection::close(CloseReason reason) {
    if (closed_) return;
    closed_ = true;
    const auto keep_alive = shared_from_this();  // on_closed drops the server's reference
    ConnectionContext& context = *context_;
    --context.stats.connections_open;
    if (reason != CloseReason::server_stop && reason != CloseReason::not_allowed) ++close_counter(context.stats, reason);
    log(context.log, reason == CloseReason::peer ? LogLevel::debug : LogLevel::info,
        "Modbus TCP: connection {} from {} closed: {}", client_.connection, peer_, to_string(reason));
    asio::error_code ignored;
    idle_timer_.cancel();
    frame_timer_.cancel();
    socket_.shutdown(asio::ip::tcp::socket::shutdown_both, ignored);
    socket_.close(ignored);
    // A target may hold this object a while longer (until it answers or drops the
    // handler): keep only what a late answer needs.
    // (Buffers of a read or write in flight are released by its aborted handler.)
    out_pending_ = protocol::Bytes{};
    if (!reading_) release_read_buffer();
    if (!writing_) out_sending_ = protocol::Bytes{};
    if (forwarded_) notify_targets();
    if (context.on_closed) context.on_closed(client_.connection);
}

void Connection::release_read_buffer() {
    rx_ = std::vector<std::uint8_t>{};
    rx_begin_ = rx_end_ = 0;
}

void Connection::notify_targets() {
    for (UnitTarget* target : context_->routes.targets()) {
        try {
            target->client_closed(client_.connection);
        } catch (const std::exception& e) {
            log(context_->log, LogLevel::error, "Modbus TCP: a target failed to drop connection {}: {}",
                client_.connection, e.what());
        }
    }
}

}  // namespace fieldbridge::northbound::modbus_tcp
