#pragma once
/// @file mqtt_bridge.hpp
/// The MQTT northbound (spec §6, docs/mqtt.md): publishes availability, device state
/// and alarms, answers commands, publishes diagnostics, through a Client seam.
///
/// Loop thread only. The bridge never waits for the broker: publications go into a
/// bounded Outbox and are handed to the client while fewer than `max_in_flight` are
/// unacknowledged; while the broker is away nothing but alarm events and command
/// results is kept (bounded), since state and alarm sets are retained values that
/// are published again, whole, on every new connection. Events and results handed to
/// the client but not confirmed when the connection broke are sent again first on
/// the next one (at least once). A lost connection or a failed attempt is retried
/// after a back-off (doubling from `reconnect_initial` up to `reconnect_max`), or as
/// soon as a probe sees a broker that was down accept connections again
/// (ReconnectSchedule); with several brokers (mqtt.uri as a list) each failed attempt
/// and each lost connection moves to the next one, wrapping to the first.
// Standard headers before asio's (see daemon/periodic.hpp).
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <asio/io_context.hpp>
#include <asio/steady_timer.hpp>
#include <nlohmann/json.hpp>

#include "config/config.hpp"
#include "engine/line_log.hpp"
#include "northbound/mqtt/alarm_tracker.hpp"
#include "northbound/mqtt/bridge_settings.hpp"
#include "northbound/mqtt/device_source.hpp"
#include "northbound/mqtt/broker_probe.hpp"
#include "northbound/mqtt/mqtt_client.hpp"
#include "northbound/mqtt/outbox.hpp"
#include "northbound/mqtt/reconnect_schedule.hpp"
#include "northbound/mqtt/state_throttle.hpp"

namespace fieldbridge::northbound::mqtt {

/// Extra sections of `<prefix>/diag` (lines and devices, Modbus TCP clients): an
/// object whose members are merged into the payload.
using DiagProvider = std::function<nlohmann::json()>;

struct BridgeStats {
    std::uint64_t connects = 0;          ///< successful connections
    std::uint64_t connect_failures = 0;
    std::uint64_t connection_losses = 0;
    std::uint64_t published = 0;         ///< acknowledged (QoS 1/2) or handed over (QoS 0)
    std::uint64_t publish_failures = 0;  ///< refused by the client or failed
    std::uint64_t dropped = 0;           ///< outbox full
    std::uint64_t resent = 0;            ///< events / results sent again after a lost connection
    std::uint64_t refused = 0;           ///< events / results the broker failed on a working connection
    std::uint64_t superseded = 0;        ///< a retained value replaced before it was sent
    std::uint64_t state_messages = 0;
    std::uint64_t alarm_events = 0;
    std::uint64_t commands = 0;
    std::uint64_t commands_failed = 0;
    std::uint64_t commands_too_large = 0;  ///< payload over max_command_bytes
    std::uint64_t commands_dropped = 0;    ///< over the client's inbound bound, never seen
    std::size_t in_flight = 0;
    std::size_t queued = 0;
};

class Bridge {
public:
    /// @p probe: the broker reachability check while reconnecting (nullptr: back-off only).
    Bridge(asio::io_context& io, BridgeSettings settings, std::unique_ptr<Client> client, engine::LogSink log = {},
           std::unique_ptr<BrokerProbe> probe = nullptr);
    ~Bridge();
    Bridge(const Bridge&) = delete;
    Bridge& operator=(const Bridge&) = delete;

    /// Replaces the devices (start-up, or a reload that rebuilt the engine). Commands
    /// in progress on the old sources still get their results.
    void set_sources(std::vector<std::shared_ptr<DeviceSource>> sources);
    void set_diag_provider(DiagProvider provider);

    /// Connects (and keeps reconnecting) and starts the timers.
    void start();
    /// Clean stop: publishes `offline` (retained), waits for it (at most
    /// stop_timeout), disconnects, then calls @p done on the loop thread. Nothing
    /// is published afterwards.
    void stop(std::function<void()> done);

    [[nodiscard]] bool connected() const noexcept;
    /// The process ends after this bridge: see Client::leave_to_process_exit().
    void leave_client_to_process_exit() noexcept;
    [[nodiscard]] BridgeStats stats() const;
    [[nodiscard]] const BridgeSettings& settings() const noexcept;

private:
    class Impl;
    std::shared_ptr<Impl> impl_;
};

}  // namespace fieldbridge::northbound::mqtt
