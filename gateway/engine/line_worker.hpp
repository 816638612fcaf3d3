#pragma once
/// @file line_worker.hpp
/// The I/O driver of one serial line, and the only owner of its port (spec §3 rule 1).
/// It runs on the daemon's asio::io_context (one thread) and drives the sans-I/O cores:
///
///     LineScheduler::next()  -> LineMaster::start()
///     LineMaster::next_action():
///         Wait{t}      -> wait for the port to be readable or until t (one timer)
///         Write{bytes} -> non-blocking writes until all are handed to the driver
///         Finished     -> LineScheduler::finished()
///         Idle         -> pick the next transaction, or sleep until submit() or
///                         LineScheduler::next_wakeup()
///
/// The port is read in every state. When it fails (open error, EIO/ENXIO on read or
/// write: USB adapter unplugged, pty closed) the worker aborts the transaction in
/// flight, marks the line down (the scheduler completes queued and new transactions
/// `line_down`), logs what failed and what to check, and retries open() with back-off
/// (reopen_initial doubling up to reopen_max) until it succeeds; then the line is up
/// again and the master's silence counts from the reopen.
///
/// Lifetime: construct, add devices through scheduler(), start(), submit() from the
/// loop thread, stop() before destruction (completes everything `cancelled`, closes
/// the port). Every submitted transaction's on_done is called exactly once, on the
/// loop thread, never from inside submit() (completions are posted).
#include <asio/io_context.hpp>
#include <functional>
#include <memory>
#include <string>

#include "engine/line_log.hpp"
#include "engine/line_master.hpp"
#include "engine/line_scheduler.hpp"
#include "engine/serial_port.hpp"
#include "engine/transaction.hpp"

namespace fieldbridge::engine {

struct LineWorkerConfig {
    std::string name;                 ///< the line's config name, for logs
    LineTimingConfig timing;
    SchedulerConfig scheduler;
    Duration reopen_initial = std::chrono::milliseconds{500};
    Duration reopen_max = std::chrono::seconds{30};
};

/// Called when the line goes up (port open) or down (port failed / closed). start()
/// reports the first state (up, or down when the first open fails); stop() reports
/// down when the line was up. Called on the loop thread.
using LineStateCallback = std::function<void(bool up, TimePoint now)>;

class LineWorker {
public:
    LineWorker(asio::io_context& io, LineWorkerConfig config, std::unique_ptr<SerialPort> port,
               LogSink log = {});
    ~LineWorker();
    LineWorker(const LineWorker&) = delete;
    LineWorker& operator=(const LineWorker&) = delete;

    /// Devices, health callback: set up before start().
    [[nodiscard]] LineScheduler& scheduler() noexcept;
    [[nodiscard]] const LineScheduler& scheduler() const noexcept;
    void set_state_callback(LineStateCallback callback);

    /// Opens the port (a failure is logged and retried with back-off, not thrown) and
    /// starts the loop. Returns at once.
    void start();
    /// Completes everything `cancelled`, closes the port, cancels timers. Idempotent.
    void stop();

    /// Queues a transaction (loop thread only).
    void submit(Transaction transaction);

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
