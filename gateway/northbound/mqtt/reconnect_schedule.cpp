#include "northbound/mqtt/reconnect_schedule.hpp"

#include <algorithm>
#include <string>
#include <utility>

namespace fieldbridge::northbound::mqtt {

using engine::LogLevel;

ReconnectSchedule::ReconnectSchedule(asio::io_context& io, ReconnectSettings settings,
                                     std::unique_ptr<BrokerProbe> probe, std::function<void()> connect,
                                     engine::LogSink log)
    : s_(settings),
      probe_(std::move(probe)),
      connect_(std::move(connect)),
      log_(std::move(log)),
      timer_(io),
      probe_timer_(io),
      backoff_(s_.initial) {}

ReconnectSchedule::~ReconnectSchedule() {
    *alive_ = false;
    cancel();
}

engine::Duration ReconnectSchedule::schedule() {
    const engine::Duration delay = backoff_;
    backoff_ = std::min(backoff_ * 2, s_.max);
    due_ = engine::Clock::now() + delay;
    timer_.expires_after(delay);
    timer_.async_wait([this, alive = std::weak_ptr<bool>(alive_)](const std::error_code& error) {
        const auto live = alive.lock();
        if (error || !live || !*live) return;
        connect_now();
    });
    if (probe_ && delay > s_.probe_period) arm_probe();
    return delay;
}

void ReconnectSchedule::reset() {
    backoff_ = s_.initial;
    seen_down_ = false;
}

void ReconnectSchedule::cancel() {
    timer_.cancel();
    probe_timer_.cancel();
    if (probe_) probe_->cancel();
}

void ReconnectSchedule::arm_probe() {
    probe_timer_.expires_after(s_.probe_period);
    probe_timer_.async_wait([this, alive = std::weak_ptr<bool>(alive_)](const std::error_code& error) {
        const auto live = alive.lock();
        if (error || !live || !*live) return;
        probe_->probe(s_.probe_timeout, [this, alive](bool reachable) {
            const auto still = alive.lock();
            if (still && *still) on_probe(reachable);
        });
    });
}

void ReconnectSchedule::on_probe(bool reachable) {
    if (!reachable) {
        seen_down_ = true;
    } else if (seen_down_) {
        const auto early = std::chrono::duration_cast<std::chrono::milliseconds>(due_ - engine::Clock::now());
        log_(LogLevel::info, "MQTT: the broker accepts connections again; connecting now (" +
                                 std::to_string(std::max<long long>(early.count(), 0)) + " ms before the back-off)");
        // Once per outage: if this attempt fails too, the broker refuses rather than
        // being down, and the back-off's pace applies again.
        seen_down_ = false;
        timer_.cancel();
        connect_now();
        return;
    }
    // Reachable but never seen down: the broker refuses MQTT itself; keep the back-off.
    if (engine::Clock::now() + s_.probe_period < due_) arm_probe();
}

void ReconnectSchedule::connect_now() {
    probe_timer_.cancel();
    if (probe_) probe_->cancel();
    connect_();
}

}  // namespace fieldbridge::northbound::mqtt
