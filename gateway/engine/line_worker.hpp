#pragma once
/// @file line_worker.hpp
/// The asio shell of one serial line, and the only owner of its port (spec §3 rule 1).
/// Every decision (which transaction, when to read, write or time out, when to reopen)
/// is the sans-I/O LineCore's (engine/line_core.hpp); the worker runs on the daemon's
/// asio::io_context (one thread) and carries out its steps: it owns the port
/// (LinePort: non-blocking reads and writes, readiness waits), two wake timers and
/// the reopen timer, posts the drives the core asks for, feeds it the answers with
/// the time from its clock seam, and delivers completions after each transition
/// (LineDelivery).
///
/// When the port fails (open error, EIO/ENXIO on read or write: USB adapter
/// unplugged, pty closed) the transaction in flight is aborted, the line goes down
/// (queued and new transactions complete `line_down`), the log says what failed and
/// what to check, and open() is retried with back-off (reopen_initial doubling up to
/// reopen_max) until it succeeds; then the line is up again and the master's silence
/// counts from the reopen.
///
/// Lifetime: construct, add devices through scheduler(), start(), submit() from the
/// loop thread, stop() before destruction (completes everything `cancelled`, closes
/// the port). Every submitted transaction's on_done is called exactly once, on the
/// loop thread, never from inside submit().
#include <asio/io_context.hpp>
#include <functional>
#include <memory>
#include <string>

#include "engine/line_core.hpp"
#include "engine/line_log.hpp"
#include "engine/line_master.hpp"
#include "engine/line_scheduler.hpp"
#include "engine/serial_port.hpp"
#include "engine/transaction.hpp"

namespace fieldbridge::engine {

using LineWorkerConfig = LineCoreConfig;

/// The default timer-slack seam: prctl(PR_SET_TIMERSLACK, 1) on the calling thread.
/// The default slack (50 us) would add up to that to every wake-up (spec section 9,
/// docs/performance.md). Per thread; harmless for the rest of the loop.
void tighten_timer_slack() noexcept;

/// What the worker asks of the system, as seams (tests pass their own).
struct LineWorkerSeams {
    /// The clock every event is stamped with.
    TimePoint (*now)() noexcept = &Clock::now;
    /// Called by start(): the loop thread times silences of a few hundred
    /// microseconds; the default sets the thread's timer slack to 1 ns.
    void (*set_timer_slack)() noexcept = &engine::tighten_timer_slack;
};

/// Called when the line goes up (port open) or down (port failed / closed). start()
/// reports the first state (up, or down when the first open fails); stop() reports
/// down when the line was up. Called on the loop thread.
using LineStateCallback = std::function<void(bool up, TimePoint now)>;

class LineWorker {
public:
    LineWorker(asio::io_context& io, LineWorkerConfig config, std::unique_ptr<SerialPort> port,
               LogSink log = {}, LineWorkerSeams seams = {});
    ~LineWorker();
    LineWorker(const LineWorker&) = delete;
    LineWorker& operator=(const LineWorker&) = delete;

    /// Devices: added before start(), updated between events. Remove them with
    /// remove_device() below: the scheduler only collects completions, the worker
    /// delivers them.
    [[nodiscard]] LineScheduler& scheduler() noexcept;
    [[nodiscard]] const LineScheduler& scheduler() const noexcept;
    void set_state_callback(LineStateCallback callback);
    /// Device online / offline, called on the loop thread after the transition.
    void set_health_callback(HealthCallback callback);

    /// Opens the port (a failure is logged and retried with back-off, not thrown) and
    /// starts the loop. Returns at once.
    void start();
    /// Completes everything `cancelled`, closes the port, cancels timers. Idempotent.
    void stop();

    /// Queues a transaction (loop thread only).
    void submit(Transaction transaction);
    /// Reload: forgets @p device; its queued transactions complete with @p status
    /// before this returns, one in flight completes with its outcome.
    void remove_device(DeviceIndex device, OutcomeStatus status);
    /// Reload: @p device's agent was retired; its queued polls complete `cancelled`
    /// before this returns, its queued requests stay and still go out.
    void drop_polls(DeviceIndex device);

    [[nodiscard]] bool line_up() const noexcept;
    [[nodiscard]] const LineMaster& master() const noexcept;
    [[nodiscard]] const LineWorkerConfig& config() const noexcept;
    /// Times the port was (re)opened after a failure.
    [[nodiscard]] std::uint64_t reopens() const noexcept;

private:
    class Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace fieldbridge::engine
