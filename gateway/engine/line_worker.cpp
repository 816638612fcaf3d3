#include "engine/line_worker.hpp"

#include <sys/prctl.h>

#include <asio/error.hpp>
#include <asio/post.hpp>
#include <asio/steady_timer.hpp>
#include <algorithm>
#include <exception>
#include <optional>
#include <stdexcept>
#include <utility>
#include <variant>
#include <vector>

#include "core/error.hpp"
#include "engine/line_worker_port.hpp"

namespace fieldbridge::engine {
namespace {

/// Waits at least this long go to the lazy timer (LineWorker::Impl::arm_wake): longer
/// than any silence, gap or turnaround, shorter than any sensible response timeout.
constexpr Duration lazy_wait = std::chrono::milliseconds{20};

/// "500 ms", "1 s", "2.5 s": for the retry messages an operator reads.
std::string duration_text(Duration duration) {
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(duration).count();
    if (ms < 1000) return std::to_string(ms) + " ms";
    std::string text = std::to_string(ms / 1000);
    if (ms % 1000 != 0) text += "." + std::to_string((ms % 1000) / 100);
    return text + " s";
}

void call_on_done(Transaction& transaction, const Outcome& outcome, const LogSink& log,
                  const std::string& line) {
    if (!transaction.on_done) return;
    try {
        transaction.on_done(outcome);
    } catch (const std::exception& error) {
        log(LogLevel::error, "line " + line + ": a completion handler threw: " + error.what());
    } catch (...) {
        log(LogLevel::error, "line " + line + ": a completion handler threw a non-standard exception");
    }
}

}  // namespace

class LineWorker::Impl {
    /// A timer that wakes drive(): when it is set for, and a generation that tells its
    /// current wait from one it replaced.
    struct WakeTimer {
        explicit WakeTimer(asio::io_context& io) : timer(io) {}
        asio::steady_timer timer;
        std::optional<TimePoint> at;  ///< set and not fired yet
        std::uint64_t generation = 0;
    };

public:
    Impl(asio::io_context& io, LineWorkerConfig config, std::unique_ptr<SerialPort> port, LogSink log)
        : io_(io),
          config_(std::move(config)),
          log_(std::move(log)),
          master_(config_.name, config_.timing, log_),
          scheduler_(scheduler_config(config_), log_),
          port_(io, std::move(port)),
          wake_(io),
          lazy_(io),
          reopen_timer_(io),
          reopen_delay_(config_.reopen_initial) {
        if (config_.reopen_initial <= Duration::zero() || config_.reopen_max < config_.reopen_initial) {
            throw core::InvalidArgument("line " + config_.name +
                                        ": reopen back-off must be positive with max >= initial");
        }
    }

    ~Impl() { stop(); }
    Impl(const Impl&) = delete;
    Impl& operator=(const Impl&) = delete;

    LineScheduler& scheduler() noexcept { return scheduler_; }
    const LineScheduler& scheduler() const noexcept { return scheduler_; }
    const LineMaster& master() const noexcept { return master_; }
    const LineWorkerConfig& config() const noexcept { return config_; }
    bool line_up() const noexcept { return line_up_; }
    std::uint64_t reopens() const noexcept { return reopens_; }
    void set_state_callback(LineStateCallback callback) { on_state_ = std::move(callback); }

    void start() {
        if (stopped_) throw std::logic_error("line " + config_.name + ": start() after stop()");
        if (started_) return;
        started_ = true;
        // The loop thread times silences of a few hundred microseconds: the default
        // timer slack (50 us) would add up to that to every wake-up (spec section 9,
        // docs/performance.md). Per thread; harmless for the rest of the loop.
        ::prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
        try_open();
    }

    void submit(Transaction transaction) {
        if (stopped_) {
            // Completed on the loop, never inside submit(); self-contained because the
            // worker may be gone by the time it runs.
            asio::post(io_, [transaction = std::move(transaction), log = log_, line = config_.name]() mutable {
                Outcome outcome;
                outcome.status = OutcomeStatus::cancelled;
                outcome.finished = Clock::now();
                outcome.attempts = transaction.attempts;
                call_on_done(transaction, outcome, log, line);
            });
            return;
        }
        // Into the inbox, handed to the scheduler by the loop: the scheduler may complete
        // a submission at once (line_down, expired, queue_full...) and that completion
        // must not run inside submit(). A submit from a completion (the usual "poll
        // again") is picked up by the running drive() before it picks the next one.
        inbox_.push_back(std::move(transaction));
        request_drive();
    }

    void stop() {
        if (stopped_) return;
        stopped_ = true;
        const TimePoint now = Clock::now();
        const bool was_up = line_up_;
        wake_.timer.cancel();
        lazy_.timer.cancel();
        reopen_timer_.cancel();
        close_port();
        if (auto finished = master_.abort(now)) {
            // Not written yet: it never went out, so it is cancelled like the queued
            // ones. Written: the device may have acted; the master's outcome stands.
            if (finished->outcome.status == OutcomeStatus::line_down) {
                finished->outcome.status = OutcomeStatus::cancelled;
            }
            scheduler_.finished(std::move(finished->transaction), finished->outcome, now);
        }
        std::vector<Transaction> pending = std::move(inbox_);
        inbox_.clear();
        for (Transaction& transaction : pending) complete_now(transaction, OutcomeStatus::cancelled, now);
        scheduler_.cancel_all(OutcomeStatus::cancelled, now);
        if (started_) log_(LogLevel::info, "line " + config_.name + ": stopped, port " + path() + " closed");
        if (was_up) notify_state(false, now);
    }

private:
    static SchedulerConfig scheduler_config(const LineWorkerConfig& config) {
        SchedulerConfig scheduler = config.scheduler;
        if (scheduler.line_name.empty()) scheduler.line_name = config.name;
        return scheduler;
    }

    const std::string& path() const noexcept { return port_.settings().path; }

    /// Wraps a handler so that it does nothing once this Impl is gone: asio may still
    /// hold aborted waits after stop() and destruction.
    template <typename Function>
    auto guarded(Function function) {
        return [alive = std::weak_ptr<char>(alive_), this, function = std::move(function)](auto&&... args) mutable {
            if (alive.expired()) return;
            function(std::forward<decltype(args)>(args)...);
        };
    }

    // ---- the loop -----------------------------------------------------------------

    void request_drive() {
        if (in_drive_ || drive_posted_ || stopped_) return;
        drive_posted_ = true;
        asio::post(io_, guarded([this] {
            drive_posted_ = false;
            drive();
        }));
    }

    /// Runs the scheduler and the master until they must wait for the port or a time.
    /// Everything that may call back into user code (submissions, finished) is
    /// followed by a fresh look at the state, because a completion may submit or stop.
    ///
    /// @p polled: called from the port's readiness handler or the wake timer, i.e.
    /// right after the reactor looked at the port. asio completes the descriptors
    /// ready in one reactor pass before the timers of that pass, so any byte that had
    /// arrived by then was read already: the port need not be read again before a
    /// write or a timeout decision (one read syscall less per transaction; the window
    /// left is the few microseconds of this handler, as with a read). A drive posted
    /// by a submission may run before a pending readiness handler: it reads first.
    void drive(bool polled = false) {
        if (in_drive_) return;
        in_drive_ = true;
        unsigned idle_rechecks = 0;
        while (true) {
            if (!inbox_.empty()) polled = false;  // submissions may complete user code now
            take_inbox();
            if (stopped_ || !port_.is_open()) break;
            TimePoint now = Clock::now();
            if (!master_.busy()) {
                polled = false;  // next() may complete expired transactions
                std::optional<Transaction> next = scheduler_.next(now);
                if (stopped_ || !port_.is_open()) {
                    if (next) complete_now(*next, OutcomeStatus::cancelled, now);
                    break;
                }
                if (next) {
                    master_.start(std::move(*next), now);
                } else if (!inbox_.empty()) {
                    continue;
                }
            }
            if (!polled && master_.state() == MasterState::waiting_silence && now >= master_.earliest_send()) {
                // About to write: take in what arrived meanwhile first, so that bytes
                // queued behind a pending readiness event still push the silence out.
                if (!read_input()) continue;
                now = Clock::now();
            }
            if ((master_.state() == MasterState::awaiting_reply || master_.state() == MasterState::discarding_echo) &&
                now >= master_.reply_decision_at()) {
                // next_action() decides the timeout: take in what arrived first. A drive
                // posted by a submission can run before the port's readiness handler when
                // the loop was held up (a slow handler, a busy machine); without this a
                // reply already in the driver's buffer would be judged a timeout, and a
                // write answered in time reported as failed.
                if (!read_input()) continue;
                now = Clock::now();
            }
            polled = false;  // what follows may run user code (completions) for a while
            LineAction action = master_.next_action(now);
            if (auto* finished = std::get_if<line_action::Finished>(&action)) {
                scheduler_.finished(std::move(finished->transaction), finished->outcome, now);
                continue;
            }
            if (auto* write = std::get_if<line_action::Write>(&action)) {
                if (write_waiting_) break;  // the writability handler resumes
                if (write_out(write->bytes)) continue;
                break;
            }
            if (const auto* wait = std::get_if<line_action::Wait>(&action)) {
                // A deadline already behind us loops at once: a timer would add a trip
                // through the reactor to every transaction.
                if (wait->until <= Clock::now()) continue;
                arm_wake(wait->until, now);
                break;
            }
            // Idle: nothing eligible now.
            if (!inbox_.empty()) continue;
            const std::optional<TimePoint> wake = scheduler_.next_wakeup(now);
            if (!wake) break;  // submit() wakes us
            if (*wake <= now && ++idle_rechecks < 3) continue;
            // "Due now" yet nothing to pick would be a scheduler inconsistency: look
            // again in a millisecond rather than spin through the reactor.
            arm_wake(*wake > now ? *wake : now + std::chrono::milliseconds{1}, now);
            break;
        }
        in_drive_ = false;
    }

    void take_inbox() {
        while (!inbox_.empty()) {
            std::swap(inbox_, draining_);
            for (Transaction& transaction : draining_) {
                if (stopped_) {
                    complete_now(transaction, OutcomeStatus::cancelled, Clock::now());
                } else {
                    scheduler_.submit(std::move(transaction), Clock::now());
                }
            }
            draining_.clear();
        }
    }

    void complete_now(Transaction& transaction, OutcomeStatus status, TimePoint now) {
        Outcome outcome;
        outcome.status = status;
        outcome.finished = now;
        outcome.attempts = transaction.attempts;
        call_on_done(transaction, outcome, log_, config_.name);
    }

    /// Wakes drive() at @p until (or earlier: drive() always looks again). Short waits
    /// (silences, gaps, turnarounds) set wake_ to the instant. Long ones (a reply's
    /// timeout, the next poll) go to lazy_, which is left alone when it is already due
    /// no later than needed: it then wakes drive() early, once per timeout period
    /// rather than per transaction, and is set again from there. Re-setting a pending
    /// timer for every request would cancel its wait (one more pass through the
    /// reactor) and update the timerfd each time (docs/performance.md, "CPU per
    /// transaction").
    void arm_wake(TimePoint until, TimePoint now) {
        if (until - now >= lazy_wait) {
            if (!lazy_.at || *lazy_.at > until) set(lazy_, until);
            return;
        }
        if (!wake_.at || *wake_.at != until) set(wake_, until);
    }

    void set(WakeTimer& wake, TimePoint until) {
        wake.at = until;
        const std::uint64_t generation = ++wake.generation;
        wake.timer.expires_at(until);
        wake.timer.async_wait(guarded([this, &wake, generation](const asio::error_code& error) {
            if (error == asio::error::operation_aborted || generation != wake.generation) return;
            wake.at.reset();
            drive(true);
        }));
    }

    // ---- port I/O -----------------------------------------------------------------

    /// Hands the request to the driver; true when all of it went (on_written called).
    bool write_out(protocol::ByteView bytes) {
        try {
            while (write_offset_ < bytes.size()) {
                const std::size_t n = port_.write_some(bytes.subspan(write_offset_));
                if (n == 0) {
                    arm_writable();
                    return false;
                }
                write_offset_ += n;
            }
        } catch (const SerialPortError& error) {
            port_failed("write", error.what());
            return false;
        }
        write_offset_ = 0;
        master_.on_written(Clock::now());
        return true;
    }

    /// Reads everything there is now into the master; false when the port failed.
    bool read_input() {
        try {
            do {
                const protocol::ByteView bytes = port_.read_some();
                if (bytes.empty()) break;
                master_.on_bytes(bytes, Clock::now());
            } while (port_.buffer_filled());
        } catch (const SerialPortError& error) {
            port_failed("read", error.what());
            return false;
        }
        return true;
    }

    void arm_readable() {
        if (read_waiting_ || !port_.is_open()) return;
        read_waiting_ = true;
        port_.wait_readable(guarded([this](const asio::error_code& error) {
            if (error == asio::error::operation_aborted) return;  // released: flags reset there
            read_waiting_ = false;
            if (stopped_ || !port_.is_open()) return;
            // A hang-up is reported as readable: read_some turns it into the error.
            if (!read_input()) {
                drive();  // completions from the failure may have submitted
                return;
            }
            arm_readable();
            drive(true);
        }));
    }

    void arm_writable() {
        write_waiting_ = true;
        port_.wait_writable(guarded([this](const asio::error_code& error) {
            if (error == asio::error::operation_aborted) return;
            write_waiting_ = false;
            drive();
        }));
    }

    void close_port() noexcept {
        port_.close();
        read_waiting_ = false;
        write_waiting_ = false;
        write_offset_ = 0;
        line_up_ = false;
    }

    // ---- failure and reopen -------------------------------------------------------

    void port_failed(const char* operation, const std::string& what) {
        const TimePoint now = Clock::now();
        close_port();
        down_ = true;
        open_attempts_ = 0;
        reopen_delay_ = config_.reopen_initial;
        // `what` names the port and says what the error usually means.
        log_(LogLevel::error, "line " + config_.name + ": " + operation + " on the port failed: " + what +
                                  "; check the adapter and its cable; retrying in " +
                                  duration_text(reopen_delay_));
        if (auto finished = master_.abort(now)) {
            scheduler_.finished(std::move(finished->transaction), finished->outcome, now);
        }
        if (stopped_) return;
        scheduler_.set_line_up(false, now);
        if (stopped_) return;
        notify_state(false, now);
        if (stopped_) return;
        schedule_reopen();
    }

    void schedule_reopen() {
        reopen_timer_.expires_after(reopen_delay_);
        reopen_timer_.async_wait(guarded([this](const asio::error_code& error) {
            if (error == asio::error::operation_aborted || stopped_) return;
            try_open();
        }));
    }

    /// Opens the port (at start or after a failure); on failure schedules the next try
    /// with the back-off doubled.
    void try_open() {
        ++open_attempts_;
        try {
            port_.open();
        } catch (const SerialPortError& error) {
            const TimePoint now = Clock::now();
            if (!down_) {
                // The first open at start: the line starts down.
                down_ = true;
                reopen_delay_ = config_.reopen_initial;
                log_(LogLevel::error, "line " + config_.name + ": cannot open " + path() + ": " +
                                          error.what() + "; check the adapter and its cable; retrying in " +
                                          duration_text(reopen_delay_));
                scheduler_.set_line_up(false, now);
                if (stopped_) return;
                notify_state(false, now);
                if (stopped_) return;
            } else {
                reopen_delay_ = std::min(reopen_delay_ * 2, config_.reopen_max);
                log_(LogLevel::warning, "line " + config_.name + ": reopening " + path() +
                                            " failed (attempt " + std::to_string(open_attempts_) +
                                            "): " + error.what() + "; retrying in " +
                                            duration_text(reopen_delay_));
            }
            schedule_reopen();
            return;
        }
        const TimePoint now = Clock::now();
        // Whatever was on the wire before is unknown: the silence counts from now.
        master_.reset(now);
        line_up_ = true;
        if (down_) {
            ++reopens_;
            log_(LogLevel::info, "line " + config_.name + ": " + path() + " reopened after " +
                                     std::to_string(open_attempts_) +
                                     (open_attempts_ == 1 ? " attempt" : " attempts") + ", " +
                                     to_string(port_.low_latency()));
        } else {
            log_(LogLevel::info, "line " + config_.name + ": " + path() + " open, " + to_string(port_.low_latency()));
        }
        down_ = false;
        open_attempts_ = 0;
        reopen_delay_ = config_.reopen_initial;
        scheduler_.set_line_up(true, now);
        arm_readable();
        notify_state(true, now);
        request_drive();
    }

    void notify_state(bool up, TimePoint now) {
        if (!on_state_) return;
        try {
            on_state_(up, now);
        } catch (const std::exception& error) {
            log_(LogLevel::error, "line " + config_.name + ": the line state callback threw: " + error.what());
        }
    }

    asio::io_context& io_;
    LineWorkerConfig config_;
    LogSink log_;
    LineMaster master_;
    LineScheduler scheduler_;
    LinePort port_;
    WakeTimer wake_;  ///< short waits, set to the instant
    WakeTimer lazy_;  ///< long waits, may wake early (arm_wake)
    asio::steady_timer reopen_timer_;
    LineStateCallback on_state_;
    std::shared_ptr<char> alive_ = std::make_shared<char>('\0');

    std::vector<Transaction> inbox_;     ///< submitted, not yet handed to the scheduler
    std::vector<Transaction> draining_;  ///< the inbox being handed over (capacity reused)
    std::size_t write_offset_ = 0;       ///< bytes of the current request already written
    Duration reopen_delay_;
    unsigned open_attempts_ = 0;  ///< since the line went down (or since start)
    std::uint64_t reopens_ = 0;
    bool started_ = false;
    bool stopped_ = false;
    bool down_ = false;  ///< an open failed or the port failed; the next open is a reopen
    bool line_up_ = false;
    bool in_drive_ = false;
    bool drive_posted_ = false;
    bool read_waiting_ = false;
    bool write_waiting_ = false;
};

LineWorker::LineWorker(asio::io_context& io, LineWorkerConfig config, std::unique_ptr<SerialPort> port,
                       LogSink log)
    : impl_(std::make_unique<Impl>(io, std::move(config), std::move(port), std::move(log))) {}

LineWorker::~LineWorker() {
    // Stopped while every member is alive: a completion may still call submit().
    impl_->stop();
}

LineScheduler& LineWorker::scheduler() noexcept { return impl_->scheduler(); }
const LineScheduler& LineWorker::scheduler() const noexcept {
    return std::as_const(*impl_).scheduler();
}
void LineWorker::set_state_callback(LineStateCallback callback) { impl_->set_state_callback(std::move(callback)); }
void LineWorker::start() { impl_->start(); }
void LineWorker::stop() { impl_->stop(); }
void LineWorker::submit(Transaction transaction) { impl_->submit(std::move(transaction)); }
bool LineWorker::line_up() const noexcept { return impl_->line_up(); }
const LineMaster& LineWorker::master() const noexcept { return impl_->master(); }
const LineWorkerConfig& LineWorker::config() const noexcept { return impl_->config(); }
std::uint64_t LineWorker::reopens() const noexcept { return impl_->reopens(); }

}  // namespace fieldbridge::engine
