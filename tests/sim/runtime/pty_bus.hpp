#pragma once
/// @file pty_bus.hpp
/// A simulated bus on a pseudo-terminal: reads the master side, feeds a BusEngine,
/// writes what the engine schedules at the scheduled moment (asio steady timers,
/// never sleeps), and performs `unplug` (close the pty, remove the link, come back
/// after a while on the same path). Single-threaded: everything runs on the
/// io_context that owns it.

#include <array>
#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>

#include <asio/io_context.hpp>
#include <asio/steady_timer.hpp>
#include <nlohmann/json.hpp>
#include <spdlog/logger.h>

#include "bus_engine.hpp"
#include "pty_open_watch.hpp"
#include "pty_port.hpp"

namespace fieldbridge::sim::runtime {

/// With wire time on, the output timer fires this much before a reply is due and the
/// bus spins to the exact instant: a timer wake-up on a virtual machine is often
/// 50-150 us late, which would count against the gateway in the benchmarks
/// (docs/simulator.md, "Wire-time precision"). Costs at most this much CPU per reply.
inline constexpr std::chrono::microseconds output_spin_lead{250};

class PtyBus {
public:
    PtyBus(asio::io_context& io, std::filesystem::path link, std::unique_ptr<BusEngine> engine,
           std::shared_ptr<spdlog::logger> log);
    ~PtyBus();
    PtyBus(const PtyBus&) = delete;
    PtyBus& operator=(const PtyBus&) = delete;

    /// Opens the pty and starts reading. Throws SimError.
    void open();
    /// Closes the pty and removes the link; pending outputs are lost. Idempotent.
    void close();
    /// The port vanishes now and comes back (same link path) after @p downtime.
    void unplug(std::chrono::nanoseconds downtime);
    /// Applies a fault spec addressed to this bus (including unplug).
    void apply_fault(const FaultSpec& spec);
    /// Advances the models (the simulator's periodic tick).
    void tick(Clock::time_point now);

    [[nodiscard]] BusEngine& engine() noexcept { return *engine_; }
    [[nodiscard]] const BusEngine& engine() const noexcept { return *engine_; }
    [[nodiscard]] const std::string& name() const noexcept { return engine_->settings().name; }
    [[nodiscard]] bool is_open() const noexcept { return port_ != nullptr; }
    [[nodiscard]] nlohmann::json stats(Clock::time_point now) const;

private:
    void start_read();
    /// A new pty: watch its slave for the gateway's opens.
    void watch_opens();
    /// The pty goes: keep its counts.
    void unwatch_opens();
    void on_read(const asio::error_code& error, std::size_t count);
    void flush_due();
    void arm_timers();
    void on_output_timer(const asio::error_code& error);
    void on_resync_timer(const asio::error_code& error);
    void on_replug_timer(const asio::error_code& error);

    asio::io_context& io_;
    std::filesystem::path link_;
    std::unique_ptr<BusEngine> engine_;
    std::shared_ptr<spdlog::logger> log_;
    std::unique_ptr<PtyPort> port_;
    /// Opens and closes of the current pty's slave by the gateway (replug: a new watch).
    std::unique_ptr<PtyOpenWatch> opens_watch_;
    std::uint64_t opens_before_ = 0;   ///< of earlier ptys (before an unplug)
    std::uint64_t closes_before_ = 0;
    asio::steady_timer output_timer_;
    asio::steady_timer resync_timer_;
    asio::steady_timer replug_timer_;
    std::optional<Clock::time_point> output_armed_;
    std::optional<Clock::time_point> resync_armed_;
    bool closed_ = true;          ///< close() called (or never opened): no replug
    std::array<std::uint8_t, 4096> rx_buffer_{};
};

}  // namespace fieldbridge::sim::runtime
