#include "engine/line_core.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "core/error.hpp"

namespace fieldbridge::engine {
namespace {

/// Waits at least this long go to the lazy timer (LineCore::arm_wake): longer than
/// any silence, gap or turnaround, shorter than any sensible response timeout.
constexpr Duration lazy_wait = std::chrono::milliseconds{20};

/// "500 ms", "1 s", "2.5 s": for the retry messages an operator reads.
std::string duration_text(Duration duration) {
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(duration).count();
    if (ms < 1000) return std::to_string(ms) + " ms";
    std::string text = std::to_string(ms / 1000);
    if (ms % 1000 != 0) text += "." + std::to_string((ms % 1000) / 100);
    return text + " s";
}

SchedulerConfig scheduler_config(const LineCoreConfig& config) {
    SchedulerConfig scheduler = config.scheduler;
    if (scheduler.line_name.empty()) scheduler.line_name = config.name;
    return scheduler;
}

const char* question_text(LineNext next) noexcept {
    switch (next) {
        case LineNext::none: return "nothing";
        case LineNext::resume: return "resume";
        case LineNext::tick: return "tick";
        case LineNext::spin: return "spin";
        case LineNext::open: return "open";
        case LineNext::read: return "read";
        case LineNext::write: return "write";
    }
    return "?";
}

}  // namespace

LineCore::LineCore(LineCoreConfig config, std::string port_path, LogSink log)
    : config_(std::move(config)),
      port_path_(std::move(port_path)),
      log_(std::move(log)),
      master_(config_.name, config_.timing, log_),
      scheduler_(scheduler_config(config_), log_),
      reopen_delay_(config_.reopen_initial) {
    if (config_.reopen_initial <= Duration::zero() || config_.reopen_max < config_.reopen_initial) {
        throw core::InvalidArgument("line " + config_.name + ": reopen back-off must be positive with max >= initial");
    }
}

LineStep LineCore::handle(TimePoint now, LineEvent&& event) {
    LineStep step;
    std::visit([&](auto& e) { on(now, e, step); }, event);
    return step;
}

bool LineCore::answered(LineNext first, LineNext second, const char* event) {
    if (asked_ == LineNext::none || (asked_ != first && asked_ != second)) {
        // Stop while the shell delivered (a completion stopped the line): the
        // question lapsed with it.
        if (port_ == PortState::stopped) return false;
        throw std::logic_error("line " + config_.name + ": " + event + " answers " + question_text(asked_) +
                               " (line core used out of order)");
    }
    asked_ = LineNext::none;
    return true;
}

void LineCore::at_rest(const char* event) const {
    if (asked_ != LineNext::none) {
        throw std::logic_error("line " + config_.name + ": " + event + " while the shell owes an answer to " +
                               question_text(asked_) + " (line core used out of order)");
    }
}

void LineCore::ask(LineNext question, LineStep& step) {
    asked_ = question;
    step.next = question;
}

// ---- life cycle ---------------------------------------------------------------------

void LineCore::on(TimePoint, line_event::Start&, LineStep& step) {
    if (port_ == PortState::stopped) throw std::logic_error("line " + config_.name + ": start() after stop()");
    if (port_ != PortState::idle || asked_ == LineNext::open) return;
    ++open_attempts_;
    ask(LineNext::open, step);
}

void LineCore::on(TimePoint now, line_event::Stop&, LineStep& step) {
    if (port_ == PortState::stopped) return;
    const bool started = port_ != PortState::idle;
    const bool was_up = port_ == PortState::up;
    port_ = PortState::stopped;
    asked_ = LineNext::none;
    opening_ = false;
    step.cancel_timers = true;
    step.close_port = true;
    exact_at_.reset();
    lazy_at_.reset();
    write_offset_ = 0;
    write_blocked_ = false;
    if (auto finished = master_.abort(now)) {
        // Not written yet: it never went out, so it is cancelled like the queued
        // ones. Written: the device may have acted; the master's outcome stands.
        if (finished->outcome.status == OutcomeStatus::line_down) finished->outcome.status = OutcomeStatus::cancelled;
        scheduler_.finished(std::move(finished->transaction), finished->outcome, now);
    }
    for (Transaction& transaction : inbox_) scheduler_.refuse(std::move(transaction), OutcomeStatus::cancelled, now);
    inbox_.clear();
    scheduler_.cancel_all(OutcomeStatus::cancelled, now);
    if (started) log_(LogLevel::info, "line " + config_.name + ": stopped, port " + port_path_ + " closed");
    if (was_up) step.line_up = false;
}

void LineCore::on(TimePoint now, line_event::Submit& event, LineStep& step) {
    if (port_ == PortState::stopped) {
        // The shell delivers it from the loop, never inside its submit().
        scheduler_.refuse(std::move(event.transaction), OutcomeStatus::cancelled, now);
        return;
    }
    if (port_ == PortState::up && asked_ == LineNext::none && !drive_posted_ && inbox_.empty() &&
        (master_.busy() || pick_wait_)) {
        // The drive loop is waiting for the transaction in flight (its reply, its
        // silence, the driver) or for the silence before the next pick, on a wake-up
        // that is already set: nothing the submission brings can change that wait. It
        // joins the queue now and competes at the next pick, which that wake-up makes;
        // a drive now would only cost a pass through the reactor and a read. A
        // refusal completes in this step (the shell delivers it from its loop).
        scheduler_.submit(std::move(event.transaction), now);
        return;
    }
    // Into the inbox, handed to the scheduler by the drive loop: a submission from a
    // completion is taken before the next transaction is picked.
    inbox_.push_back(std::move(event.transaction));
    request_drive(step);
}

void LineCore::on(TimePoint now, line_event::RemoveDevice& event, LineStep&) {
    if (event.polls_only) {
        scheduler_.drop_polls(event.device, event.status, now);
    } else {
        scheduler_.remove_device(event.device, event.status, now);
    }
}

void LineCore::request_drive(LineStep& step) {
    // While the shell delivers (next == resume) the running drive takes the inbox.
    if (drive_posted_ || asked_ == LineNext::resume) return;
    drive_posted_ = true;
    step.post_drive = true;
}

// ---- the port: open, failure, reopen ------------------------------------------------

void LineCore::on(TimePoint, line_event::OpenPending&, LineStep&) {
    if (!answered(LineNext::open, LineNext::open, "OpenPending")) return;
    // The connect runs; Opened or OpenFailed comes as an event of its own, and the
    // line stays down (or not started) meanwhile.
    opening_ = true;
}

bool LineCore::open_answered(const char* event) {
    if (opening_) {
        opening_ = false;
        return port_ != PortState::stopped;
    }
    return answered(LineNext::open, LineNext::open, event);
}

void LineCore::on(TimePoint now, line_event::Opened& event, LineStep& step) {
    if (!open_answered("Opened")) return;
    // Whatever was on the wire before is unknown: the silence counts from now.
    master_.reset(now);
    scheduler_.line_opened(now);
    if (port_ == PortState::down) {
        ++reopens_;
        log_(LogLevel::info, "line " + config_.name + ": " + port_path_ + " reopened after " +
                                 std::to_string(open_attempts_) + (open_attempts_ == 1 ? " attempt" : " attempts") +
                                 ", " + event.detail);
    } else {
        log_(LogLevel::info, "line " + config_.name + ": " + port_path_ + " open, " + event.detail);
    }
    port_ = PortState::up;
    quiet_ = RepeatedFailure{};
    open_attempts_ = 0;
    reopen_delay_ = config_.reopen_initial;
    step.watch_readable = true;
    step.line_up = true;
    request_drive(step);
}

void LineCore::on(TimePoint now, line_event::OpenFailed& event, LineStep& step) {
    if (!open_answered("OpenFailed")) return;
    if (port_ != PortState::down) {
        // The first open at start: the line starts down.
        port_ = PortState::down;
        reopen_delay_ = config_.reopen_initial;
        log_(LogLevel::error, "line " + config_.name + ": cannot open " + port_path_ + ": " + event.what +
                                  cable_advice() + "; retrying in " + duration_text(reopen_delay_));
        scheduler_.cancel_all(OutcomeStatus::line_down, now);
        step.line_up = false;
    } else {
        reopen_delay_ = std::min(reopen_delay_ * 2, config_.reopen_max);
        log_reopen_failure(now, event.what);
    }
    schedule_reopen(now, step);
}

void LineCore::log_reopen_failure(TimePoint now, const std::string& what) {
    // A device server switched off for an hour is thousands of attempts at a short
    // back-off: once the back-off is at its maximum, a failure like the last one
    // logged (also at the maximum) is logged at most once a minute, with a count.
    const bool at_max = reopen_delay_ == config_.reopen_max;
    if (at_max && quiet_.at_max && what == quiet_.what && now - quiet_.logged_at < repeat_log_interval) {
        ++quiet_.suppressed;
        return;
    }
    const std::string also = quiet_.suppressed == 0 ? std::string{}
                                                    : " (" + std::to_string(quiet_.suppressed) +
                                                          " more failures like it since the last such line)";
    log_(LogLevel::warning, "line " + config_.name + ": reopening " + port_path_ + " failed (attempt " +
                                std::to_string(open_attempts_) + "): " + what + "; retrying in " +
                                duration_text(reopen_delay_) + also);
    quiet_ = RepeatedFailure{what, now, at_max, 0};
}

void LineCore::on(TimePoint, line_event::ReopenDue&, LineStep& step) {
    if (port_ != PortState::down) return;
    at_rest("ReopenDue");
    ++open_attempts_;
    ask(LineNext::open, step);
}

const char* LineCore::cable_advice() const noexcept {
    // A device server's errors carry their own advice (engine/tcp_stream_port.cpp).
    return config_.timing.stream ? "" : "; check the adapter and its cable";
}

void LineCore::schedule_reopen(TimePoint now, LineStep& step) { step.reopen_at = now + reopen_delay_; }

void LineCore::on(TimePoint now, line_event::PortFailed& event, LineStep& step) {
    if (!answered(LineNext::read, LineNext::write, "PortFailed")) return;
    port_failed(now, event.operation, event.what, step);
    // The failure's completions go first; then submissions complete line_down.
    begin_drive(now, false, step);
}

void LineCore::port_failed(TimePoint now, const char* operation, const std::string& what, LineStep& step) {
    step.close_port = true;
    write_offset_ = 0;
    write_blocked_ = false;
    port_ = PortState::down;
    open_attempts_ = 0;
    reopen_delay_ = config_.reopen_initial;
    // `what` names the port and says what the error usually means.
    log_(LogLevel::error, "line " + config_.name + ": " + operation + " on the port failed: " + what +
                              cable_advice() + "; retrying in " + duration_text(reopen_delay_));
    if (auto finished = master_.abort(now)) {
        scheduler_.finished(std::move(finished->transaction), finished->outcome, now);
    }
    // Queued requests fail now (a read the abort re-queued for its retry included);
    // take_inbox() turns later submissions away until the port is open again.
    scheduler_.cancel_all(OutcomeStatus::line_down, now);
    step.line_up = false;
    schedule_reopen(now, step);
}

// ---- readiness, timers, reads and writes --------------------------------------------

void LineCore::on(TimePoint now, line_event::Drive&, LineStep& step) {
    drive_posted_ = false;
    if (port_ == PortState::stopped) return;
    at_rest("Drive");
    // Posted by a submission: it may run before a pending readiness handler, so it
    // reads before deciding (polled = false).
    begin_drive(now, false, step);
}

void LineCore::on(TimePoint, line_event::Readable&, LineStep& step) {
    if (port_ != PortState::up) return;
    at_rest("Readable");
    // A hang-up is reported as readable: the read turns it into PortFailed.
    read_for_readiness_ = true;
    ask(LineNext::read, step);
}

void LineCore::on(TimePoint now, line_event::Writable&, LineStep& step) {
    if (port_ != PortState::up) return;
    at_rest("Writable");
    write_blocked_ = false;
    begin_drive(now, false, step);
}

void LineCore::on(TimePoint now, line_event::TimerFired& event, LineStep& step) {
    (event.timer == WakeTimer::exact ? exact_at_ : lazy_at_).reset();
    if (port_ == PortState::stopped) return;
    at_rest("TimerFired");
    begin_drive(now, true, step);
}

void LineCore::on(TimePoint now, line_event::BytesRead& event, LineStep& step) {
    if (!answered(LineNext::read, LineNext::read, "BytesRead")) return;
    if (!event.bytes.empty()) master_.on_bytes(event.bytes, now);
    if (event.buffer_full) {
        // Read until the buffer is not full: what is left would only be seen on the
        // next readiness report, after a decision it may change.
        ask(LineNext::read, step);
        return;
    }
    if (read_for_readiness_) {
        read_for_readiness_ = false;
        step.watch_readable = true;
        // asio completes the descriptors ready in one reactor pass before the timers
        // of that pass, so any byte that had arrived was read now (polled).
        begin_drive(now, true, step);
        return;
    }
    fresh_read_ = true;  // the decision the read was for comes next
    drive(now, step);
}

void LineCore::on(TimePoint now, line_event::Written&, LineStep& step) {
    if (!answered(LineNext::write, LineNext::write, "Written")) return;
    write_offset_ = 0;
    master_.on_written(now);
    drive(now, step);
}

void LineCore::on(TimePoint, line_event::WriteBlocked& event, LineStep& step) {
    if (!answered(LineNext::write, LineNext::write, "WriteBlocked")) return;
    write_offset_ += event.accepted;
    write_blocked_ = true;
    step.watch_writable = true;  // Writable resumes the drive
}

void LineCore::on(TimePoint now, line_event::Resume&, LineStep& step) {
    if (asked_ == LineNext::spin) {
        // The spin reached the instant. The reactor has not looked at the port during
        // it: the drive reads it before the write (polled false), so a byte that came
        // meanwhile still pushes the silence out.
        asked_ = LineNext::none;
        polled_ = false;
        drive(now, step);
        return;
    }
    const LineNext question = asked_;
    if (!answered(LineNext::resume, LineNext::tick, "Resume")) return;
    if (question == LineNext::tick) {
        // A deadline already behind us loops at once: a timer would add a trip through
        // the reactor to every transaction.
        if (wait_until_ <= now) {
            drive(now, step);
        } else {
            wait_for(wait_until_, now, step);
        }
        return;
    }
    // The deliveries ran user code for a while: the port must be read again before
    // a decision.
    polled_ = false;
    drive(now, step);
}

// ---- the drive loop -----------------------------------------------------------------

void LineCore::begin_drive(TimePoint now, bool polled, LineStep& step) {
    polled_ = polled;
    fresh_read_ = false;
    idle_rechecks_ = 0;
    drive(now, step);
}

void LineCore::take_inbox(TimePoint now) {
    // The port's state is the core's alone: while it is down, submissions complete
    // `line_down`; before the first open they queue.
    for (Transaction& transaction : inbox_) {
        if (port_ == PortState::down) {
            scheduler_.turn_away(std::move(transaction), OutcomeStatus::line_down, now);
        } else {
            scheduler_.submit(std::move(transaction), now);
        }
    }
    inbox_.clear();
}

/// Runs the scheduler and the master until they wait for the port, a time or a
/// delivery. @p now is fixed for the pass: every path that needs a newer one asks
/// (read, write, tick) and goes on with the answer's.
void LineCore::drive(TimePoint now, LineStep& step) {
    pick_wait_ = false;
    while (true) {
        take_inbox(now);
        if (has_deliveries()) {
            // Delivered before the next pick: a completion's submission (the usual
            // "poll again") competes for the line like any other.
            polled_ = false;
            fresh_read_ = false;
            ask(LineNext::resume, step);
            return;
        }
        if (port_ != PortState::up) return;
        if (!master_.busy()) {
            // The next transaction is picked when the silence before it ends (with a
            // spin lead: when the spin begins), not when the line becomes free: what
            // is submitted during the silence competes for it.
            const TimePoint pick_at = master_.earliest_send() - std::max(config_.spin_lead, Duration::zero());
            if (now < pick_at) {
                // What can no longer start completes now, as a pick now would do it.
                scheduler_.expire(now);
                if (has_deliveries()) continue;
                const std::optional<TimePoint> wake = scheduler_.next_wakeup(now);
                if (!wake) return;  // a submission wakes us
                arm_wake(std::max(*wake, pick_at), now, step);
                // Woken at the pick: a submission meanwhile needs no drive of its own.
                pick_wait_ = *wake <= pick_at;
                return;
            }
            // A pick with nothing to deliver ran no handler: a readiness report or a
            // timer that began this pass still stands for the port (polled_).
            if (std::optional<Transaction> next = scheduler_.next(now)) master_.start(std::move(*next), now);
            if (has_deliveries()) continue;
        }
        if (!fresh_read_) {
            const MasterState state = master_.state();
            if (!polled_ && state == MasterState::waiting_silence && now >= master_.earliest_send()) {
                // About to write: take in what arrived meanwhile first, so that bytes
                // queued behind a pending readiness event still push the silence out.
                read_for_readiness_ = false;
                ask(LineNext::read, step);
                return;
            }
            if ((state == MasterState::awaiting_reply || state == MasterState::discarding_echo) &&
                now >= master_.reply_decision_at()) {
                // next_action() decides the timeout: take in what arrived first. A drive
                // posted by a submission can run before the port's readiness handler when
                // the loop was held up (a slow handler, a busy machine); without this a
                // reply already in the driver's buffer would be judged a timeout, and a
                // write answered in time reported as failed.
                read_for_readiness_ = false;
                ask(LineNext::read, step);
                return;
            }
        }
        fresh_read_ = false;
        polled_ = false;
        LineAction action = master_.next_action(now);
        if (auto* finished = std::get_if<line_action::Finished>(&action)) {
            scheduler_.finished(std::move(finished->transaction), finished->outcome, now);
            continue;
        }
        if (const auto* write = std::get_if<line_action::Write>(&action)) {
            if (write_blocked_) return;  // Writable resumes
            step.write = write->bytes.subspan(write_offset_);
            ask(LineNext::write, step);
            return;
        }
        if (const auto* wait = std::get_if<line_action::Wait>(&action)) {
            // Checked against a fresh clock (tick): the time this pass took may have
            // brought the deadline.
            wait_until_ = wait->until;
            ask(LineNext::tick, step);
            return;
        }
        // Idle: nothing eligible now.
        const std::optional<TimePoint> wake = scheduler_.next_wakeup(now);
        if (!wake) return;  // a submission wakes us
        if (*wake <= now && ++idle_rechecks_ < 3) continue;
        // "Due now" yet nothing to pick would be a scheduler inconsistency: look
        // again in a millisecond rather than spin through the reactor.
        arm_wake(*wake > now ? *wake : now + std::chrono::milliseconds{1}, now, step);
        return;
    }
}

/// Precise silence timing (config_.spin_lead > 0): the drive picks the next request
/// spin_lead before the silence ends (drive(): the exact timer, set that early, covers
/// the timer's own lateness; a silence shorter than the lead is picked at once) and
/// the master encodes it; from there the shell spins to the instant, and the drive
/// reads the port and writes. Every other wait (replies, polls, broadcasts settling)
/// is left to the timers.
void LineCore::wait_for(TimePoint until, TimePoint now, LineStep& step) {
    const Duration lead = config_.spin_lead;
    if (lead <= Duration::zero() || master_.state() != MasterState::waiting_silence) {
        arm_wake(until, now, step);
        return;
    }
    if (until - now <= lead) {
        step.spin_until = until;
        ask(LineNext::spin, step);
        return;
    }
    arm_wake(until - lead, now, step);
}

/// Wakes the drive at @p until (or earlier: the drive always looks again). Short waits
/// (silences, gaps, turnarounds) set the exact timer to the instant. Long ones (a
/// reply's timeout, the next poll) go to the lazy timer, which is left alone when it
/// is already due no later than needed: it then wakes the drive early, once per
/// timeout period rather than per transaction, and is set again from there. Re-setting
/// a pending timer for every request would cancel its wait (one more pass through the
/// reactor) and update the timerfd each time (docs/performance.md, "CPU per
/// transaction").
void LineCore::arm_wake(TimePoint until, TimePoint now, LineStep& step) {
    if (until - now >= lazy_wait) {
        if (!lazy_at_ || *lazy_at_ > until) {
            lazy_at_ = until;
            step.lazy_wake = until;
        }
        return;
    }
    if (!exact_at_ || *exact_at_ != until) {
        exact_at_ = until;
        step.exact_wake = until;
    }
}

}  // namespace fieldbridge::engine
