#pragma once
/// @file periodic.hpp
/// A duty of the event loop that runs every period (watchdog pings, STATUS refresh).

// Standard headers before asio's: asio 1.22 chooses aligned_alloc or operator new
// for its handler memory from a libstdc++ macro that exists only once a standard
// header was read; two choices in one program are an ODR violation (ASan:
// alloc-dealloc-mismatch).
#include <chrono>
#include <functional>

#include <asio/io_context.hpp>
#include <asio/steady_timer.hpp>

namespace fieldbridge::daemon {

/// Calls a function on the loop every period, on the monotonic clock
/// (asio::steady_timer). Deadlines advance by whole periods from the first one, so
/// a late tick does not shift the following ones. Not copyable or movable: the
/// pending wait refers to it.
class Periodic {
public:
    Periodic(asio::io_context& io, std::chrono::steady_clock::duration period, std::function<void()> tick);
    Periodic(const Periodic&) = delete;
    Periodic& operator=(const Periodic&) = delete;
    Periodic(Periodic&&) = delete;
    Periodic& operator=(Periodic&&) = delete;
    ~Periodic();

    /// Starts ticking: the first tick runs now (synchronously) when @p tick_now,
    /// else one period from now. Calling it while running restarts the schedule.
    void start(bool tick_now);
    /// Stops ticking; no tick runs after this returns.
    void cancel() noexcept;

    [[nodiscard]] bool running() const noexcept { return running_; }
    [[nodiscard]] std::chrono::steady_clock::duration period() const noexcept { return period_; }

private:
    void arm();

    asio::steady_timer timer_;
    std::chrono::steady_clock::duration period_;
    std::function<void()> tick_;
    std::chrono::steady_clock::time_point next_{};
    bool running_ = false;
    /// Incremented by start/cancel: a completion of an older wait is ignored even
    /// when it was already queued as successful before the cancel.
    unsigned generation_ = 0;
};

}  // namespace fieldbridge::daemon
