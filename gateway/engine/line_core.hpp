#pragma once
/// @file line_core.hpp
/// One serial line as one sans-I/O state machine: the scheduler (which transaction
/// next), the line master (timing and framing of the one in flight), the inbox of
/// submissions and the port's state (up, down, open attempts, reopen back-off). It
/// never touches a port, a timer or a clock: its one transition function, handle(),
/// takes `now` and an event and returns the step the shell carries out. The shells:
/// engine/line_worker.cpp (asio, the daemon), scan/line_link.cpp (ppoll, the scan
/// tool) and the engine loop test (virtual time).
///
/// A step is effects, deliveries, then at most one question (`next`):
///
///     effects     close the port; cancel the timers; set the exact or the lazy wake
///                 timer (their expiry is TimerFired); set the reopen timer
///                 (ReopenDue); watch the port for readable / writable; post a Drive
///     deliveries  the scheduler's health changes then completions, called by the
///                 shell (LineDelivery) after the step: a handler may submit (the next
///                 event) or stop; then `line_up` (the line went up or down)
///     next        open the port -> Opened / OpenFailed (or OpenPending: a TCP
///                 connect runs, Opened / OpenFailed follow as events); read it once -> BytesRead /
///                 PortFailed; write these bytes -> Written / WriteBlocked /
///                 PortFailed; resume (after the deliveries) or tick (with a fresh
///                 `now`) -> Resume; spin (busy-wait until `spin_until`, then a
///                 `now` at or after it) -> Resume
///
/// The drive loop (what the old LineWorker::drive() did): take the inbox into the
/// scheduler; when the master is free, wait for the silence before the next request
/// to end (with a spin lead: for the spin to begin), then pick the next transaction;
/// read the port before a write or a timeout decision unless the reactor just looked
/// at it (`polled`); hand out the master's write; wait for its deadline (short waits
/// on the exact timer, long ones on a lazy timer that may wake early: arm_wake; with
/// a spin lead, the silence before a request ends in a spin: the request, picked and
/// encoded at the spin's start, is written within microseconds of the instant); and
/// when nothing is eligible, wait for the scheduler's next wake-up or a submission.
/// Completions are delivered before the next transaction is picked, so a handler's
/// submission competes for it, as before; so does one made during the silence.
///
/// A submission posts a Drive only when the loop is not already waiting on a wake-up
/// that ends in a pass of the drive: while a transaction is in flight (its silence,
/// its reply, a blocked write) or the silence before the next pick runs on a timer,
/// it goes straight to the scheduler and is considered at the next pick; a refusal
/// (queue full, device offline...) is then among the Submit step's deliveries, which
/// the shell hands out from its loop, never inside its own submit(), as after Stop.
///
/// Every submitted transaction completes exactly once: through the scheduler (its
/// outcome), `cancelled` by Stop, `line_down` while the port is down.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "engine/line_log.hpp"
#include "engine/line_master.hpp"
#include "engine/line_scheduler.hpp"
#include "engine/transaction.hpp"
#include "protocol/bytes.hpp"

namespace fieldbridge::engine {

struct LineCoreConfig {
    std::string name;  ///< the line's config name, for logs
    LineTimingConfig timing;
    SchedulerConfig scheduler;
    Duration reopen_initial = std::chrono::milliseconds{500};
    Duration reopen_max = std::chrono::seconds{30};
    /// Precise silence timing: a request waiting for its silence (or turnaround) is
    /// woken this long before the instant and the shell spins to it (LineNext::spin);
    /// zero: the exact timer is set to the instant itself. The daemon's lead is
    /// config::LineConfig::precise_timing_lead, longer than a timer wake-up is late on
    /// the machines measured (50-150 us on the development VM), so the spin, not the
    /// timer, decides the instant.
    Duration spin_lead = Duration::zero();
};

/// The shell's two wake timers (LineCore::arm_wake).
enum class WakeTimer : std::uint8_t {
    exact,  ///< short waits (silence, gap, turnaround), set to the instant
    lazy,   ///< long waits (a reply's timeout, the next poll); may fire early
};

namespace line_event {
/// Open the port and begin (the worker's start()).
struct Start {};
/// Complete everything `cancelled`, close the port, cancel the timers. Idempotent.
struct Stop {};
/// A transaction for the line (its completion is delivered, never called here). The
/// step may carry deliveries: the refusal of a submission after Stop, or while the
/// line waits (see the file comment).
struct Submit {
    Transaction transaction;
};
/// Reload: forget a device; its queued transactions complete with @p status.
struct RemoveDevice {
    DeviceIndex device = 0;
    OutcomeStatus status = OutcomeStatus::cancelled;
    /// Only its queued polls go (a retired agent's: nobody waits for them); the
    /// device and its other requests stay until they drain.
    bool polls_only = false;
};
/// The Drive the step asked to post runs now.
struct Drive {};
/// The readiness wait on the port completed (data or a hang-up).
struct Readable {};
/// The writability wait completed.
struct Writable {};
struct TimerFired {
    WakeTimer timer = WakeTimer::exact;
};
struct ReopenDue {};
/// Answer to next == open: the port is open; @p detail says what the driver made of
/// the low-latency request (for the log).
struct Opened {
    std::string detail;
};
/// Answer to next == open: the open only began (a TCP connect); Opened or
/// OpenFailed follows later as an event of its own, not as an answer.
struct OpenPending {};
/// Answer to next == open: it failed; @p what names the port and the cause.
struct OpenFailed {
    std::string what;
};
/// Answer to next == read: what one read brought (empty: nothing); @p buffer_full:
/// the read filled the buffer, more may be waiting.
struct BytesRead {
    protocol::ByteView bytes;
    bool buffer_full = false;
};
/// Answer to next == write: the driver took every byte.
struct Written {};
/// Answer to next == write: the driver took @p accepted bytes, then would block.
struct WriteBlocked {
    std::size_t accepted = 0;
};
/// Answer to next == read or write: the port failed (EIO, hang-up); @p operation is
/// "read" or "write", @p what names the port and says what the error usually means.
struct PortFailed {
    const char* operation = "read";
    std::string what;
};
/// Answer to next == resume (the deliveries ran) or next == tick (a fresh `now`).
struct Resume {};
}  // namespace line_event

using LineEvent =
    std::variant<line_event::Start, line_event::Stop, line_event::Submit, line_event::RemoveDevice,
                 line_event::Drive, line_event::Readable, line_event::Writable, line_event::TimerFired,
                 line_event::ReopenDue, line_event::OpenPending, line_event::Opened, line_event::OpenFailed,
                 line_event::BytesRead,
                 line_event::Written, line_event::WriteBlocked, line_event::PortFailed, line_event::Resume>;

/// The one answer a step waits for (see the file comment).
enum class LineNext : std::uint8_t { none, resume, tick, spin, open, read, write };

/// What the shell does after one transition, in this order: the effects, the
/// deliveries (LineDelivery), `line_up`, then `next`. `next` is spin, open, read or
/// write only in a step with nothing to deliver, so no handler runs between the
/// question and its answer.
struct LineStep {
    bool close_port = false;
    bool cancel_timers = false;  ///< the wake timers and the reopen timer
    std::optional<TimePoint> exact_wake;  ///< (re)set WakeTimer::exact to this instant
    std::optional<TimePoint> lazy_wake;   ///< (re)set WakeTimer::lazy to this instant
    std::optional<TimePoint> reopen_at;   ///< then ReopenDue
    bool watch_readable = false;  ///< then Readable (one wait at a time)
    bool watch_writable = false;  ///< then Writable
    bool post_drive = false;      ///< Drive from the loop, never from inside this call
    std::optional<bool> line_up;  ///< the line went up / down: tell its owner
    LineNext next = LineNext::none;
    protocol::ByteView write;  ///< next == write: valid until the next event
    /// next == spin: busy-wait (no sleep, no reactor) until the clock reaches this
    /// instant, at most the spin lead after the step's `now`; then Resume.
    TimePoint spin_until{};
};

class LineCore {
public:
    /// Throws core::InvalidArgument for a back-off that cannot work or an impossible
    /// character format. @p port_path is what the logs call the port.
    LineCore(LineCoreConfig config, std::string port_path, LogSink log = {});

    /// The transition function. Throws std::logic_error for Start after Stop and for
    /// an answer to a question that was not asked.
    [[nodiscard]] LineStep handle(TimePoint now, LineEvent&& event);

    /// Something to deliver (LineDelivery takes it from scheduler()).
    [[nodiscard]] bool has_deliveries() const noexcept {
        return scheduler_.has_completions() || scheduler_.has_health_changes();
    }

    /// Devices: add and update before or between events; the deliveries.
    [[nodiscard]] LineScheduler& scheduler() noexcept { return scheduler_; }
    [[nodiscard]] const LineScheduler& scheduler() const noexcept { return scheduler_; }
    [[nodiscard]] const LineMaster& master() const noexcept { return master_; }
    [[nodiscard]] const LineCoreConfig& config() const noexcept { return config_; }
    [[nodiscard]] const std::string& port_path() const noexcept { return port_path_; }
    [[nodiscard]] bool line_up() const noexcept { return port_ == PortState::up; }
    [[nodiscard]] bool stopped() const noexcept { return port_ == PortState::stopped; }
    /// Times the port was opened after a failure (or after a failed first open).
    [[nodiscard]] std::uint64_t reopens() const noexcept { return reopens_; }

private:
    enum class PortState : std::uint8_t {
        idle,     ///< not started
        up,       ///< open
        down,     ///< an open failed or the port failed: the next open is a reopen
        stopped,  ///< for good
    };

    void on(TimePoint now, line_event::Start& event, LineStep& step);
    void on(TimePoint now, line_event::Stop& event, LineStep& step);
    void on(TimePoint now, line_event::Submit& event, LineStep& step);
    void on(TimePoint now, line_event::RemoveDevice& event, LineStep& step);
    void on(TimePoint now, line_event::Drive& event, LineStep& step);
    void on(TimePoint now, line_event::Readable& event, LineStep& step);
    void on(TimePoint now, line_event::Writable& event, LineStep& step);
    void on(TimePoint now, line_event::TimerFired& event, LineStep& step);
    void on(TimePoint now, line_event::ReopenDue& event, LineStep& step);
    void on(TimePoint now, line_event::OpenPending& event, LineStep& step);
    void on(TimePoint now, line_event::Opened& event, LineStep& step);
    void on(TimePoint now, line_event::OpenFailed& event, LineStep& step);
    void on(TimePoint now, line_event::BytesRead& event, LineStep& step);
    void on(TimePoint now, line_event::Written& event, LineStep& step);
    void on(TimePoint now, line_event::WriteBlocked& event, LineStep& step);
    void on(TimePoint now, line_event::PortFailed& event, LineStep& step);
    void on(TimePoint now, line_event::Resume& event, LineStep& step);

    /// Opened / OpenFailed: the answer to open, or the end of a pending open.
    [[nodiscard]] bool open_answered(const char* event);
    [[nodiscard]] const char* cable_advice() const noexcept;
    void log_reopen_failure(TimePoint now, const std::string& what);
    /// False for a stale answer after Stop; throws for an answer nobody asked for.
    [[nodiscard]] bool answered(LineNext first, LineNext second, const char* event);
    /// Throws std::logic_error when the shell owes an answer (a reactor event arrived
    /// between a question and its answer: a shell bug).
    void at_rest(const char* event) const;
    void ask(LineNext question, LineStep& step);
    void request_drive(LineStep& step);
    /// A new pass of the drive loop; @p polled: the reactor just looked at the port.
    void begin_drive(TimePoint now, bool polled, LineStep& step);
    void drive(TimePoint now, LineStep& step);
    void take_inbox(TimePoint now);
    void arm_wake(TimePoint until, TimePoint now, LineStep& step);
    /// The tick's deadline is in the future: spin to it, or set a wake timer.
    void wait_for(TimePoint until, TimePoint now, LineStep& step);
    void port_failed(TimePoint now, const char* operation, const std::string& what, LineStep& step);
    void schedule_reopen(TimePoint now, LineStep& step);

    LineCoreConfig config_;
    std::string port_path_;
    LogSink log_;
    LineMaster master_;
    LineScheduler scheduler_;

    std::vector<Transaction> inbox_;  ///< submitted, not yet handed to the scheduler
    PortState port_ = PortState::idle;
    LineNext asked_ = LineNext::none;  ///< the question the shell is answering
    bool opening_ = false;  ///< OpenPending: the shell reports the open's end later
    /// The last reopen failure logged (log_reopen_failure).
    struct RepeatedFailure {
        std::string what;
        TimePoint logged_at{};
        bool at_max = false;  ///< the back-off was at its maximum then
        unsigned suppressed = 0;
    };
    static constexpr Duration repeat_log_interval = std::chrono::minutes{1};
    RepeatedFailure quiet_;
    Duration reopen_delay_;
    unsigned open_attempts_ = 0;  ///< since the line went down (or since start)
    std::uint64_t reopens_ = 0;

    // The drive loop.
    bool drive_posted_ = false;
    /// At rest, master idle, a wake timer set for the silence's end: the pick then
    /// takes what was submitted meanwhile (on(Submit) posts no drive).
    bool pick_wait_ = false;
    bool polled_ = false;        ///< the reactor just looked at the port (drive())
    bool fresh_read_ = false;    ///< the port was read for this decision: go on to it
    bool read_for_readiness_ = false;  ///< the read answers Readable, not a decision
    unsigned idle_rechecks_ = 0;
    TimePoint wait_until_{};     ///< next == tick: the master's Wait
    std::size_t write_offset_ = 0;  ///< bytes of the current request already written
    bool write_blocked_ = false;    ///< waiting for Writable
    std::optional<TimePoint> exact_at_;  ///< WakeTimer::exact set and not fired
    std::optional<TimePoint> lazy_at_;   ///< WakeTimer::lazy set and not fired
};

}  // namespace fieldbridge::engine
