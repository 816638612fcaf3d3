#include "daemon/periodic.hpp"

#include <stdexcept>
#include <system_error>
#include <utility>

#include "core/error.hpp"

namespace fieldbridge::daemon {

Periodic::Periodic(asio::io_context& io, std::chrono::steady_clock::duration period, std::function<void()> tick)
    : timer_(io), period_(period), tick_(std::move(tick)) {
    if (period_ <= std::chrono::steady_clock::duration::zero()) {
        throw core::InvalidArgument("Periodic: the period must be positive");
    }
}

Periodic::~Periodic() { cancel(); }

void Periodic::start(bool tick_now) {
    cancel();
    running_ = true;
    next_ = std::chrono::steady_clock::now() + period_;
    arm();
    if (tick_now) {
        tick_();
    }
}

void Periodic::cancel() noexcept {
    running_ = false;
    ++generation_;
    timer_.cancel();
}

void Periodic::arm() {
    timer_.expires_at(next_);
    timer_.async_wait([this, generation = generation_](const std::error_code& error) {
        if (error || generation != generation_ || !running_) {
            return;
        }
        const auto now = std::chrono::steady_clock::now();
        // Skip deadlines already missed (the loop was blocked): the next one is in
        // the future, so a stall never turns into a burst of ticks.
        while (next_ <= now) {
            next_ += period_;
        }
        arm();
        tick_();
    });
}

}  // namespace fieldbridge::daemon
