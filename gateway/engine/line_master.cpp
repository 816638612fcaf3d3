#include "engine/line_master.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "core/error.hpp"
#include "engine/line_codec.hpp"

namespace fieldbridge::engine {
namespace {

bool is_ascii(const Transaction& transaction) noexcept {
    return std::holds_alternative<AsciiPayload>(transaction.payload);
}

void append_hex_byte(std::string& out, std::uint8_t value) {
    constexpr const char* digits = "0123456789ABCDEF";
    out += "0x";
    out += digits[value >> 4];
    out += digits[value & 0x0F];
}

}  // namespace

const char* to_string(MasterState state) noexcept {
    switch (state) {
        case MasterState::idle: return "idle";
        case MasterState::waiting_silence: return "waiting_silence";
        case MasterState::sending: return "sending";
        case MasterState::discarding_echo: return "discarding_echo";
        case MasterState::awaiting_reply: return "awaiting_reply";
        case MasterState::settling_broadcast: return "settling_broadcast";
        case MasterState::complete: return "complete";
    }
    return "unknown";
}

LineMaster::LineMaster(std::string line_name, LineTimingConfig config, LogSink log)
    : name_(std::move(line_name)),
      config_(config),
      timing_(config.format(), config.inter_frame),
      log_(std::move(log)) {}

void LineMaster::reset(TimePoint now) {
    // Whatever was on the wire before the port opened is unknown: count the silence
    // from the moment we started listening.
    last_rx_ = now;
    guard_until_ = now;
}

TimePoint LineMaster::last_activity() const noexcept { return std::max(last_tx_end_, last_rx_); }

TimePoint LineMaster::earliest_send() const noexcept {
    Duration silence = std::max<Duration>(timing_.t3_5(), config_.request_gap);
    if (transaction_) silence = std::max(silence, transaction_->delay_before);
    return std::max(last_activity() + silence, guard_until_);
}

std::string LineMaster::describe() const {
    std::string text = "line " + name_;
    if (transaction_) {
        text += " #" + std::to_string(transaction_->id);
        if (is_broadcast(*transaction_)) {
            text += " broadcast ";
        } else {
            text += " device " + std::to_string(transaction_->device) + " address ";
        }
        append_hex_byte(text, transaction_->address);
    }
    return text;
}

void LineMaster::transition(MasterState next, TimePoint now, const char* why) {
    const MasterState previous = state_;
    if (log_.enabled(LogLevel::debug)) {
        log_(LogLevel::debug, describe() + ": " + to_string(previous) + " -> " + to_string(next) +
                                  " (" + why + ")");
    }
    state_ = next;
    state_since_ = now;
    switch (next) {
        case MasterState::idle:
            request_.clear();
            rx_.clear();
            written_ = false;
            break;
        case MasterState::waiting_silence:
            rx_.clear();
            echo_seen_ = 0;
            echo_differs_ = false;
            run_wrong_address_ = false;
            written_ = false;
            break;
        case MasterState::sending:
            break;
        case MasterState::discarding_echo:
        case MasterState::awaiting_reply:
            if (previous == MasterState::sending) {
                // WTEC ASCII (seed 003, 1.1): a reply must come within the frame
                // timeout T and its characters within t of each other.
                const bool ascii = is_ascii(*transaction_);
                reply_deadline_ = last_tx_end_ + (ascii ? config_.ascii_frame_timeout
                                                        : config_.response_timeout);
                gap_limit_ = config_.stream ? config_.frame_gap
                                            : (ascii ? config_.ascii_char_timeout : config_.byte_timeout);
                hard_deadline_ = reply_deadline_ +
                                 timing_.wire_time(max_reply_size(*transaction_)) + gap_limit_;
            }
            run_wrong_address_ = false;
            break;
        case MasterState::settling_broadcast:
            // Modbus over Serial Line V1.02, 2.1: after a broadcast the master waits
            // a turnaround delay so every slave has processed it, on top of t3.5.
            settle_until_ = last_tx_end_ + timing_.t3_5() + config_.broadcast_delay;
            break;
        case MasterState::complete:
            break;
    }
}

void LineMaster::start(Transaction transaction, TimePoint now) {
    if (transaction_) {
        throw std::logic_error(describe() + ": start() while a transaction is in flight; "
                                            "the scheduler must pick only when the line is free");
    }
    transaction_ = std::move(transaction);
    outcome_.reset();
    started_ = now;
    std::optional<std::string> refused;
    try {
        request_ = encode_wire_request(*transaction_);
    } catch (const core::InvalidArgument& error) {
        refused = error.what();
    }
    transition(MasterState::waiting_silence, now, "started");
    if (refused) {
        log_(LogLevel::error, describe() + ": request cannot be encoded, not sent (" + *refused +
                                  "); the device profile built an invalid request, report it");
        finish(OutcomeStatus::invalid_request, {}, now, "request cannot be encoded");
    }
}

void LineMaster::finish(OutcomeStatus status, Reply reply, TimePoint now, const char* why) {
    Outcome outcome;
    outcome.status = status;
    outcome.reply = std::move(reply);
    outcome.finished = now;
    outcome.attempts = transaction_->attempts;
    switch (status) {
        case OutcomeStatus::ok: ++counters_.replies; break;
        case OutcomeStatus::timeout: ++counters_.timeouts; break;
        case OutcomeStatus::expired: ++counters_.expired; break;
        default: break;
    }
    if (!rx_.empty()) {
        counters_.garbage_bytes += rx_.size();
        rx_.clear();
    }
    counters_.busy_time += now - started_;
    if (written_) latency_.record(now - started_);
    outcome_ = std::move(outcome);
    transition(MasterState::complete, now, why);
}

line_action::Finished LineMaster::hand_out(TimePoint now) {
    transition(MasterState::idle, now, to_string(outcome_->status));
    line_action::Finished done{std::move(*transaction_), std::move(*outcome_)};
    transaction_.reset();
    outcome_.reset();
    return done;
}

LineAction LineMaster::next_action(TimePoint now) {
    switch (state_) {
        case MasterState::idle:
            return line_action::Idle{};
        case MasterState::waiting_silence: {
            const TimePoint earliest = earliest_send();
            // Rule 9: a command that cannot START before its deadline is never sent.
            if (transaction_->deadline && std::max(now, earliest) >= *transaction_->deadline) {
                finish(OutcomeStatus::expired, {}, now, "deadline passed before the line was free");
                return hand_out(now);
            }
            if (now < earliest) return line_action::Wait{earliest};
            transition(MasterState::sending, now, "silence observed");
            return line_action::Write{request_};
        }
        case MasterState::sending:
            return line_action::Write{request_};
        case MasterState::discarding_echo:
        case MasterState::awaiting_reply:
            return wait_for_reply(now);
        case MasterState::settling_broadcast:
            if (now < settle_until_) return line_action::Wait{settle_until_};
            finish(OutcomeStatus::broadcast_sent, {}, now, "broadcast settled");
            return hand_out(now);
        case MasterState::complete:
            return hand_out(now);
    }
    return line_action::Idle{};
}

TimePoint LineMaster::reply_decision_at() const noexcept {
    if (!rx_.empty()) return std::min(last_rx_ + gap_limit_, hard_deadline_);
    return reply_deadline_;
}

LineAction LineMaster::wait_for_reply(TimePoint now) {
    const bool receiving = state_ == MasterState::awaiting_reply && !rx_.empty();
    if (receiving && now >= last_rx_ + gap_limit_) {
        // The gap ended the frame (RTU: a silence ends a frame, 2.5.1.1; ASCII: the
        // inter-character timeout t): what is there will never complete.
        drop_partial();
    }
    if (now >= hard_deadline_ || (rx_.empty() && now >= reply_deadline_)) {
        finish(OutcomeStatus::timeout, {}, now, "no valid reply in time");
        return hand_out(now);
    }
    return line_action::Wait{reply_decision_at()};
}

void LineMaster::on_written(TimePoint now) {
    if (state_ != MasterState::sending) {
        throw std::logic_error(describe() + ": on_written() in state " + to_string(state_) +
                               "; call it once after a Write action");
    }
    // The port took the bytes now; the last one is physically out n characters later.
    last_tx_end_ = now + timing_.wire_time(request_.size());
    counters_.bytes_tx += request_.size();
    ++transaction_->attempts;
    written_ = true;
    if (is_broadcast(*transaction_)) {
        ++counters_.broadcasts;
        transition(MasterState::settling_broadcast, now, "broadcast written");
        return;
    }
    ++counters_.requests;
    if (config_.local_echo && echo_seen_ < request_.size()) {
        transition(MasterState::discarding_echo, now, "request written");
        return;
    }
    transition(MasterState::awaiting_reply, now, "request written");
    scan(now);
}

protocol::ByteView LineMaster::take_echo(protocol::ByteView bytes) {
    if (!config_.local_echo) return bytes;
    std::size_t taken = 0;
    while (echo_seen_ < request_.size() && taken < bytes.size()) {
        if (bytes[taken] != request_[echo_seen_]) echo_differs_ = true;
        ++echo_seen_;
        ++taken;
    }
    if (taken > 0 && echo_seen_ == request_.size() && echo_differs_) {
        ++counters_.echo_mismatch;
        log_(LogLevel::warning, describe() + ": local echo differs from the request sent; "
                                             "check the adapter's echo setting and the wiring");
    }
    return bytes.subspan(taken);
}

void LineMaster::on_bytes(protocol::ByteView bytes, TimePoint now) {
    if (bytes.empty()) return;
    counters_.bytes_rx += bytes.size();
    // RTU frames are separated by at least t3.5 of silence (Modbus over Serial Line
    // V1.02, 2.5.1.1): a longer gap starts a new run of bytes.
    if (now - last_rx_ > timing_.t3_5()) run_wrong_address_ = false;
    last_rx_ = now;
    switch (state_) {
        case MasterState::idle:
        case MasterState::waiting_silence:
        case MasterState::complete:
            // Nothing is expected: stray bytes, or a late reply to a timed-out request.
            counters_.garbage_bytes += bytes.size();
            return;
        case MasterState::settling_broadcast:
            counters_.garbage_bytes += take_echo(bytes).size();
            return;
        case MasterState::sending:
        case MasterState::discarding_echo:
        case MasterState::awaiting_reply: {
            if (late_on_stream(now)) {
                counters_.garbage_bytes += bytes.size();
                if (log_.enabled(LogLevel::debug)) {
                    log_(LogLevel::debug, describe() + ": dropped " + std::to_string(bytes.size()) +
                                              " bytes that came before the request could have left the device "
                                              "server (a late reply to an earlier request)");
                }
                return;
            }
            const protocol::ByteView rest = take_echo(bytes);
            rx_.insert(rx_.end(), rest.begin(), rest.end());
            if (state_ == MasterState::discarding_echo && echo_seen_ == request_.size()) {
                transition(MasterState::awaiting_reply, now, "local echo discarded");
            }
            if (state_ == MasterState::awaiting_reply) scan(now);
            return;
        }
    }
}

bool LineMaster::late_on_stream(TimePoint now) const noexcept {
    // Over TCP the request reaches the far side's line only after it was written,
    // and takes its wire time there: no byte of its reply can arrive before
    // on_written + request bytes x tc (last_tx_end_). Whatever comes earlier, and
    // before a reply began, answers an earlier request that timed out: dropped, never
    // matched to this one. (On a serial line such bytes would collide with the
    // request on the wire.)
    if (!config_.stream || !rx_.empty()) return false;
    return state_ == MasterState::sending || now < last_tx_end_;
}

void LineMaster::scan(TimePoint now) {
    while (state_ == MasterState::awaiting_reply && !rx_.empty()) {
        ReplyScan result = scan_reply(rx_, *transaction_);
        if (result.kind == ReplyScan::Kind::need_more || result.consumed == 0) return;
        if (result.kind == ReplyScan::Kind::dropped) {
            // A whole frame from the device asked (its address, a good CRC) that does
            // not answer the request (a length or an echo that does not fit): the
            // device did answer, so say so now instead of waiting for a timeout.
            const bool misfit = result.framed && result.error != protocol::DecodeError::wrong_address;
            drop(std::min(result.consumed, rx_.size()), result.error, result.framed);
            // On a TCP line a frame with more bytes behind it in the same segment is an
            // earlier request's late reply (below): the scan goes on.
            if (misfit && !(config_.stream && !rx_.empty())) {
                counters_.garbage_bytes += rx_.size();
                rx_.clear();
                guard_until_ = now + config_.turnaround;
                finish(OutcomeStatus::bad_reply, {}, now, "reply does not fit the request");
                return;
            }
            continue;
        }
        counters_.garbage_bytes += result.skipped;
        if (config_.stream && result.consumed < rx_.size()) {
            // A TCP line: more bytes came after a whole reply. The device answers once
            // per request, so the earlier frame answered an earlier request (held by
            // the device server and sent with the new one): the newest frame is the
            // answer. Dropped, never matched; the scan goes on with what follows.
            counters_.garbage_bytes += result.consumed - result.skipped;
            if (log_.enabled(LogLevel::debug)) {
                log_(LogLevel::debug, describe() + ": dropped a whole reply followed by more bytes in the same "
                                                   "segment (a late reply to an earlier request)");
            }
            rx_.erase(rx_.begin(), rx_.begin() + static_cast<std::ptrdiff_t>(result.consumed));
            continue;
        }
        // Bytes after the reply in the same read belong to nothing we asked for.
        counters_.garbage_bytes += rx_.size() - std::min(result.consumed, rx_.size());
        rx_.clear();
        guard_until_ = now + config_.turnaround;
        finish(OutcomeStatus::ok, std::move(result.reply), now, "valid reply");
    }
}

void LineMaster::drop(std::size_t count, protocol::DecodeError why, bool framed) {
    if (framed) {
        // A whole frame that is not our answer: another slave (ASCII carries the
        // address in a checked frame) or a reply that does not match the request.
        if (why == protocol::DecodeError::wrong_address) {
            ++counters_.wrong_address;
        } else {
            ++counters_.bad_replies;
        }
    } else if (why == protocol::DecodeError::bad_crc) {
        ++counters_.crc_errors;
    } else {
        counters_.garbage_bytes += count;
        // RTU bytes from another slave are dropped as they arrive, often one at a
        // time: count one per run of bytes, not one per byte.
        if (why == protocol::DecodeError::wrong_address && !run_wrong_address_) {
            ++counters_.wrong_address;
            run_wrong_address_ = true;
        }
    }
    if (log_.enabled(LogLevel::debug)) {
        log_(LogLevel::debug, describe() + ": dropped " + std::to_string(count) + " received bytes (" +
                                  std::string(protocol::to_string(why)) + ")");
    }
    rx_.erase(rx_.begin(), rx_.begin() + static_cast<std::ptrdiff_t>(count));
}

void LineMaster::drop_partial() {
    counters_.garbage_bytes += rx_.size();
    if (log_.enabled(LogLevel::debug)) {
        log_(LogLevel::debug, describe() + ": dropped " + std::to_string(rx_.size()) +
                                  " bytes of an unfinished frame after an inter-character gap");
    }
    rx_.clear();
    run_wrong_address_ = false;
}

std::optional<line_action::Finished> LineMaster::abort(TimePoint now) {
    if (!transaction_) return std::nullopt;
    if (state_ != MasterState::complete) {
        OutcomeStatus status = OutcomeStatus::line_down;
        if (written_ || state_ == MasterState::sending) {
            // The bytes may have reached the device: never pretend it was not sent.
            status = is_broadcast(*transaction_) ? OutcomeStatus::broadcast_sent : OutcomeStatus::timeout;
        }
        finish(status, {}, now, "port failed");
    }
    return hand_out(now);
}

}  // namespace fieldbridge::engine
