#pragma once
/// @file line_master.hpp
/// The sans-I/O master of one half-duplex serial line: timing and framing of the ONE
/// transaction in flight (product spec section 3, rules 1 and 11). It never touches a
/// port or a clock; the line core (engine/line_core.hpp) drives it with time points
/// and bytes:
///
///     master.start(std::move(transaction), now);
///     loop:
///       switch (master.next_action(now)):
///         Wait{t}      -> wait for readable bytes or until t; on_bytes(bytes, now)
///         Write{bytes} -> hand all bytes to the port; on_written(now)
///         Finished{tx, outcome} -> scheduler.finished(std::move(tx), outcome, now)
///         Idle         -> pick the next transaction
///
/// The core has the port read in every state (stray bytes count as wire activity and
/// push the next request's silence out).
///
/// States (one transition function resets the deadlines and logs at debug level):
///
///     idle -> waiting_silence -> sending -> [discarding_echo] -> awaiting_reply -> complete -> idle
///                                       \-> settling_broadcast -> complete -> idle
///
/// Timing rules:
///  - a request is written no earlier than the last byte on the wire (sent or
///    received, garbage included) + max(t3.5, transaction.delay_before), nor earlier
///    than the last reply + turnaround (the two guards overlap, they do not add up:
///    product spec section 9 counts one t3.5 between a reply and the next request);
///  - a transaction whose deadline comes before it can start is finished `expired`
///    without being written (rule 9);
///  - the end of transmission is computed: on_written(now) + bytes x tc;
///  - Modbus-RTU: no byte of the reply by end + response_timeout -> timeout; once a
///    reply is arriving, byte_timeout bounds each gap; a partial frame whose gap
///    expires is dropped (garbage) and the wait goes on until response_timeout; the
///    whole wait never exceeds response_timeout + the longest frame's wire time +
///    byte_timeout. WTEC ASCII uses ascii_frame_timeout and ascii_char_timeout.
///  - a broadcast is written, then the line settles for t3.5 + turnaround, then it
///    finishes `broadcast_sent`; no reply is awaited.
///  - a TCP line (config.stream, a serial device server): a reply ends at its
///    predicted length or at a gap of frame_gap; bytes that arrive before the request
///    can have crossed the far side's line (written + its wire time) are a late reply
///    to an earlier request, and dropped; the silence before a request is
///    max(t3.5, request_gap) on every line.
///  - local echo (2-wire adapters): the first bytes received after a write are
///    compared with the bytes sent and discarded, exactly as many as were sent.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <variant>

#include "engine/line_log.hpp"
#include "engine/line_stats.hpp"
#include "engine/line_timing.hpp"
#include "engine/transaction.hpp"
#include "protocol/bytes.hpp"
#include "protocol/decode_result.hpp"

namespace fieldbridge::engine {

enum class MasterState : std::uint8_t {
    idle,                ///< nothing in flight
    waiting_silence,     ///< started; waiting for silence, turnaround and delay_before
    sending,             ///< Write handed out; waiting for on_written
    discarding_echo,     ///< local echo of the request still expected
    awaiting_reply,      ///< framing the reply; response / byte timers as backstop
    settling_broadcast,  ///< broadcast written; t3.5 + turnaround before it is done
    complete,            ///< outcome decided; next_action hands it out
};

[[nodiscard]] const char* to_string(MasterState state) noexcept;

namespace line_action {
/// Nothing in flight: start the next transaction.
struct Idle {};
/// Wait for bytes (always read the port) or until @p until, then call next_action.
struct Wait {
    TimePoint until;
};
/// Hand all of @p bytes to the port, then call on_written. The view stays valid until
/// the transaction is finished.
struct Write {
    protocol::ByteView bytes;
};
/// The transaction is done: pass both to LineScheduler::finished.
struct Finished {
    Transaction transaction;
    Outcome outcome;
};
}  // namespace line_action

using LineAction =
    std::variant<line_action::Idle, line_action::Wait, line_action::Write, line_action::Finished>;

class LineMaster {
public:
    /// Throws core::InvalidArgument for an impossible character format (see LineTiming).
    LineMaster(std::string line_name, LineTimingConfig config, LogSink log = {});

    /// The port was (re)opened at @p now: the silence counts from here. Counters stay.
    void reset(TimePoint now);

    /// Takes the next transaction. Precondition: !busy() (throws std::logic_error
    /// otherwise: the scheduler picks only when the line is free). A request the
    /// codecs refuse finishes `invalid_request` at the next next_action.
    void start(Transaction transaction, TimePoint now);

    /// What the worker does now; may decide timeouts and expiry (it is the only place
    /// time advances for the master).
    [[nodiscard]] LineAction next_action(TimePoint now);

    /// All bytes of the Write were handed to the port at @p now.
    void on_written(TimePoint now);

    /// Bytes read from the port at @p now (any state: idle bytes are garbage).
    void on_bytes(protocol::ByteView bytes, TimePoint now);

    /// The port failed: hands back the transaction in flight, if any. Not yet written:
    /// `line_down`; written (the device may have acted): `timeout`, or `broadcast_sent`
    /// for a broadcast.
    [[nodiscard]] std::optional<line_action::Finished> abort(TimePoint now);

    [[nodiscard]] bool busy() const noexcept { return state_ != MasterState::idle; }
    [[nodiscard]] MasterState state() const noexcept { return state_; }
    /// The earliest time the current (or a next) request may be written.
    [[nodiscard]] TimePoint earliest_send() const noexcept;
    /// While a reply is awaited: the earliest time next_action() may decide without
    /// new bytes (a partial frame's gap expired, or a timeout). Before it, reading the
    /// port first cannot change what next_action() returns.
    [[nodiscard]] TimePoint reply_decision_at() const noexcept;
    [[nodiscard]] const LineCounters& counters() const noexcept { return counters_; }
    /// start -> finished, for transactions that went on the wire.
    [[nodiscard]] const LatencyHistogram& latency() const noexcept { return latency_; }
    [[nodiscard]] const LineTiming& timing() const noexcept { return timing_; }
    [[nodiscard]] const LineTimingConfig& config() const noexcept { return config_; }
    [[nodiscard]] const std::string& name() const noexcept { return name_; }

private:
    void transition(MasterState next, TimePoint now, const char* why);
    void finish(OutcomeStatus status, Reply reply, TimePoint now, const char* why);
    [[nodiscard]] line_action::Finished hand_out(TimePoint now);
    /// Consumes the local echo at the front of @p bytes; returns what follows it.
    [[nodiscard]] protocol::ByteView take_echo(protocol::ByteView bytes);
    /// A TCP line: bytes now cannot begin the reply to the request in flight.
    [[nodiscard]] bool late_on_stream(TimePoint now) const noexcept;
    void scan(TimePoint now);
    void drop(std::size_t count, protocol::DecodeError why, bool framed);
    void drop_partial();
    [[nodiscard]] LineAction wait_for_reply(TimePoint now);
    [[nodiscard]] TimePoint last_activity() const noexcept;
    [[nodiscard]] std::string describe() const;

    std::string name_;
    LineTimingConfig config_;
    LineTiming timing_;
    LogSink log_;

    MasterState state_ = MasterState::idle;
    std::optional<Transaction> transaction_;
    std::optional<Outcome> outcome_;
    bool written_ = false;     ///< the request went to the port in this run
    protocol::Bytes request_;  ///< bytes of the request on the wire
    protocol::Bytes rx_;       ///< received after the echo, not yet framed
    std::size_t echo_seen_ = 0;
    bool echo_differs_ = false;
    bool run_wrong_address_ = false;  ///< this run of bytes was already counted as another slave's

    TimePoint started_{};
    TimePoint state_since_{};
    TimePoint last_tx_end_{};    ///< last bit of our last request on the wire
    TimePoint last_rx_{};        ///< last byte received, whatever it was
    TimePoint guard_until_{};    ///< turnaround after a reply
    TimePoint reply_deadline_{};
    TimePoint hard_deadline_{};
    TimePoint settle_until_{};
    Duration gap_limit_{};

    LineCounters counters_;
    LatencyHistogram latency_;
};

}  // namespace fieldbridge::engine
