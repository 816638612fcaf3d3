#pragma once
/// @file reconnect_schedule.hpp
/// When the bridge tries the broker again: after a back-off that doubles from
/// `initial` up to `max` and starts again from `initial` after a success; and, while
/// a wait is longer than the probe period, a cheap TCP probe of the broker's port
/// every probe period, so that a broker that was seen down is connected to as soon
/// as it accepts connections again rather than when the back-off ends (issue 15: a
/// 20 s outage left a 16 s back-off; now the state is back within about one probe
/// period). A broker that stays reachable but refuses the MQTT or TLS connection
/// (credentials, certificates) is still only tried at the back-off's pace.
///
/// Loop thread only.
// Standard headers before asio's (see daemon/periodic.hpp).
#include <chrono>
#include <functional>
#include <memory>

#include <asio/io_context.hpp>
#include <asio/steady_timer.hpp>

#include "engine/line_log.hpp"
#include "engine/transaction.hpp"
#include "northbound/mqtt/broker_probe.hpp"

namespace fieldbridge::northbound::mqtt {

struct ReconnectSettings {
    engine::Duration initial = std::chrono::seconds{1};
    engine::Duration max = std::chrono::seconds{60};
    /// Waits longer than this are cut short by a probe that finds the broker back.
    engine::Duration probe_period = std::chrono::seconds{1};
    std::chrono::milliseconds probe_timeout{800};
};

class ReconnectSchedule {
public:
    /// @p connect starts one attempt. @p probe may be null (then only the back-off).
    ReconnectSchedule(asio::io_context& io, ReconnectSettings settings, std::unique_ptr<BrokerProbe> probe,
                      std::function<void()> connect, engine::LogSink log = {});
    ~ReconnectSchedule();
    ReconnectSchedule(const ReconnectSchedule&) = delete;
    ReconnectSchedule& operator=(const ReconnectSchedule&) = delete;

    /// After a failed attempt or a lost connection: connect once the back-off has
    /// passed, or earlier when the broker comes back. Returns the back-off.
    engine::Duration schedule();
    /// Connected: the next back-off starts from `initial`.
    void reset();
    /// Nothing more is started (stop).
    void cancel();

private:
    void arm_probe();
    void on_probe(bool reachable);
    void connect_now();

    ReconnectSettings s_;
    std::unique_ptr<BrokerProbe> probe_;
    std::function<void()> connect_;
    engine::LogSink log_;
    asio::steady_timer timer_;
    asio::steady_timer probe_timer_;
    engine::Duration backoff_;
    engine::TimePoint due_{};
    /// A probe found the port closed since the last connection (or the last early
    /// attempt): the next open port means the broker came back. Kept across waits, so
    /// a broker back at the start of a wait is noticed at the first probe.
    bool seen_down_ = false;
    std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace fieldbridge::northbound::mqtt
