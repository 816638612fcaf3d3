#pragma once
/// @file daemon.hpp
/// The gateway process: one asio::io_context on the main thread and the duties
/// that run on it.
///
/// Duties of the loop (each an asynchronous chain on the io_context):
///  1. signals (asio::signal_set: the OS handler only writes to a self-pipe, the
///     handler below runs on the loop): SIGTERM/SIGINT stop, SIGHUP reloads;
///  2. start-up: components start in order, READY=1 once the readiness barrier
///     completes (every listener a component announced is up);
///  3. the systemd watchdog: WATCHDOG=1 every half WatchdogSec, from the loop
///     itself, so a blocked loop stops the pings and systemd restarts the service;
///  4. STATUS=: the one-line summary, refreshed every status period when it changed;
///  5. the components' own I/O (serial lines, TCP clients, MQTT), which they run
///     on context();
///  6. shutdown: STOPPING=1, components stop in reverse order, the loop ends when
///     all have finished or after the stop timeout.

// Standard headers before asio's: asio 1.22 chooses aligned_alloc or operator new
// for its handler memory from a libstdc++ macro that exists only once a standard
// header was read; two choices in one program are an ODR violation (ASan:
// alloc-dealloc-mismatch).
#include <chrono>
#include <exception>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <asio/io_context.hpp>
#include <asio/signal_set.hpp>
#include <asio/steady_timer.hpp>
#include <spdlog/logger.h>

#include "config/config.hpp"
#include "daemon/completion_barrier.hpp"
#include "daemon/component.hpp"
#include "daemon/config_source.hpp"
#include "daemon/periodic.hpp"
#include "daemon/service_manager.hpp"
#include "daemon/status_board.hpp"

namespace fieldbridge::daemon {

/// Configuration reloads since start, by outcome (the Prometheus export reads them).
struct ReloadCounts {
    std::uint64_t ok = 0;        ///< the new configuration was applied
    std::uint64_t rejected = 0;  ///< it could not be loaded or applied: the previous one stays
};

struct DaemonOptions {
    /// Re-read on SIGHUP.
    std::filesystem::path config_file;
    /// --log-level: wins over gateway.log_level, also after a reload.
    std::optional<config::LogLevel> log_level_override;
    /// How often STATUS= is recomputed (sent only when it changed).
    std::chrono::milliseconds status_period{std::chrono::seconds{5}};
    /// How long components may take to finish their work after SIGTERM. Below
    /// the unit's TimeoutStopSec= (15 s), so the daemon, not systemd's SIGKILL,
    /// decides what is logged.
    std::chrono::milliseconds stop_timeout{std::chrono::seconds{5}};
};

class Daemon {
public:
    enum class Phase { starting, running, stopping, stopped };

    /// @p initial is the configuration main() already loaded from
    /// options.config_file; @p load re-reads that file on SIGHUP. @p manager and
    /// the components must outlive the Daemon. Installs the signal handlers
    /// (SIGTERM, SIGINT, SIGHUP) at once, so that a signal sent before run() is
    /// queued instead of killing the process.
    Daemon(DaemonOptions options, std::shared_ptr<const config::Config> initial, ConfigLoader load,
           ServiceManager& manager, std::shared_ptr<spdlog::logger> logger);
    Daemon(const Daemon&) = delete;
    Daemon& operator=(const Daemon&) = delete;
    Daemon(Daemon&&) = delete;
    Daemon& operator=(Daemon&&) = delete;
    ~Daemon();

    /// The loop every component runs its I/O on.
    [[nodiscard]] asio::io_context& context() noexcept { return io_; }
    [[nodiscard]] const std::shared_ptr<spdlog::logger>& logger() const noexcept { return logger_; }
    /// The configuration in force (replaced by a successful reload).
    [[nodiscard]] const std::shared_ptr<const config::Config>& config() const noexcept { return config_; }
    [[nodiscard]] Phase phase() const noexcept { return phase_; }
    [[nodiscard]] const ReloadCounts& reloads() const noexcept { return reloads_; }

    /// Registers @p component (not owned). Before run() only.
    void add_component(Component& component);
    /// Adds a part to the STATUS= line ("0 TCP clients"); any time, loop thread.
    void add_status(StatusContributor contributor);

    /// Runs the loop until the gateway has stopped. Returns the exit code:
    /// exit_ok after SIGTERM/SIGINT, exit_failure after a start-up failure, a
    /// fatal error reported with fail(), or an exception escaping a handler.
    [[nodiscard]] int run();

    /// What SIGHUP does; loop thread only. During start-up the reload is deferred
    /// until READY; while stopping it is ignored.
    void request_reload();
    /// What SIGTERM/SIGINT do; loop thread only. A second request while stopping
    /// ends the loop at once.
    void request_stop(const std::string& reason);
    /// A component's fatal error (@p reason says what failed and what to do): logs
    /// it, stops the gateway, and run() returns exit_failure. Loop thread only.
    void fail(const std::string& reason);

private:
    void wait_for_signal();
    void on_signal(int signal_number);
    void start_components();
    void on_ready();
    /// Starts reading the file on a thread of its own (the loop keeps running).
    void reload();
    /// On the loop once the file is read: rejects it, or prepares and applies it.
    void finish_reload(std::shared_ptr<const config::Config> next, std::exception_ptr error, double read_ms);
    /// Reload, first phase: every started component prepares @p next; when one
    /// cannot, the prepared ones abandon, the rejection is logged and kept for
    /// STATUS=, and false is returned.
    [[nodiscard]] bool prepare(const config::Config& next);
    void finish();
    /// Sends @p state to the service manager, logged at debug level (pings excepted).
    void notify(const std::string& state);
    void apply_log_level();
    void publish_status(bool force);
    [[nodiscard]] std::string phase_note() const;

    DaemonOptions options_;
    std::shared_ptr<const config::Config> config_;
    ConfigLoader load_;
    ServiceManager& manager_;
    std::shared_ptr<spdlog::logger> logger_;

    asio::io_context io_{1};
    asio::signal_set signals_;
    asio::steady_timer stop_timer_;
    std::optional<Periodic> watchdog_;
    Periodic status_refresh_;
    StatusBoard status_;

    std::vector<Component*> components_;
    std::size_t started_ = 0;  ///< components whose start() returned normally
    CompletionBarrier readiness_;
    std::unique_ptr<CompletionBarrier> stopped_;

    Phase phase_ = Phase::starting;
    bool ran_ = false;
    bool reload_pending_ = false;
    std::thread loading_;        ///< reads the file of a reload in progress
    bool reload_again_ = false;  ///< SIGHUP while reading: read once more afterwards
    bool last_reload_rejected_ = false;
    std::string rejection_;  ///< why the last reload was rejected, when a component refused it
    ReloadCounts reloads_;
    int exit_code_ = 0;
};

}  // namespace fieldbridge::daemon
