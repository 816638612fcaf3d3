#pragma once
/// @file session.hpp
/// The Sparkplug B edge node's session rules (Sparkplug 3.0, "Operational Behavior",
/// "Topics and Messages", "Payloads"), as a pure state machine: the caller reports
/// events (a connection made or lost, the primary host's STATE, devices coming,
/// going and changing, a rebirth request, a reload, a stop, the passing of time) and
/// carries out the actions returned, in order (set the will, subscribe, publish,
/// disconnect and walk to the next server, log a warning). No MQTT, no bytes, no
/// clock: docs/sparkplug-session.md, "Design", says how the daemon glues it.
///
/// The caller's loop, per connection attempt:
///   bd = bdseq_store.next();   apply(session.connecting(bd));   connect (with that will)
///   on CONNACK:  apply(session.connected(now))
///   on loss:     apply(session.connection_lost())  and reconnect (next server on failure)
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "northbound/sparkplug/payload.hpp"
#include "northbound/sparkplug_session/host_state.hpp"
#include "northbound/sparkplug_session/offline_buffer.hpp"
#include "northbound/sparkplug_session/topics.hpp"

namespace fieldbridge::northbound::sparkplug_session {

using SteadyClock = std::chrono::steady_clock;

/// When an event happens: monotonic time for the rate rule, wall-clock time for the
/// payloads' timestamps.
struct Instant {
    SteadyClock::time_point mono{};
    std::uint64_t utc_ms = 0;  ///< ms since the Unix epoch, UTC
};

struct SessionSettings {
    NodeIdentity node;
    std::string primary_host_id;  ///< empty: no primary host, births right after CONNACK
    bool aliases = true;
    /// No DDATA of one device sooner than this after the previous one (mqtt.min_interval).
    std::chrono::milliseconds min_interval{0};
    std::size_t offline_max_messages = 20000;
    std::size_t offline_max_bytes = 16 * 1024 * 1024;
};

/// A device as the session publishes it: its Sparkplug device ID (the configured
/// device name) and every metric with its name, datatype, current value and, when
/// the catalogue gives them, alias and properties.
struct DeviceMetrics {
    std::string name;
    std::vector<sparkplug::Metric> metrics;
};

/// Register @p payload as the will of the next CONNECT.
struct SetWill {
    std::string topic;
    sparkplug::Payload payload;
    int qos = 1;
    bool retain = false;
    bool operator==(const SetWill&) const = default;
};
struct Subscribe {
    std::string topic;
    int qos = 1;
    bool operator==(const Subscribe&) const = default;
};
struct Unsubscribe {
    std::string topic;
    bool operator==(const Unsubscribe&) const = default;
};
struct Publish {
    std::string topic;
    sparkplug::Payload payload;
    int qos = 0;
    bool retain = false;
    bool operator==(const Publish&) const = default;
};
/// Send DISCONNECT (after the publications before it are delivered); with
/// @p next_server, the next connection goes to the next server of the list.
struct Disconnect {
    bool next_server = false;
    bool operator==(const Disconnect&) const = default;
};
/// A line for the log, at warning level; outside text in it is already quoted.
struct Warning {
    std::string text;
    bool operator==(const Warning&) const = default;
};
using Action = std::variant<SetWill, Subscribe, Unsubscribe, Publish, Disconnect, Warning>;
using Actions = std::vector<Action>;

enum class Phase {
    disconnected,      ///< no MQTT session (before the first, or after a loss or a walk)
    connecting,        ///< the will is set, CONNECT under way
    waiting_for_host,  ///< connected, subscribed, no births until the primary host is online
    online,            ///< births published: data flows
    stopped,           ///< stop() was called: nothing more
};

struct SessionCounters {
    std::uint64_t malformed_host_states = 0;  ///< STATE payloads ignored as malformed
    std::uint64_t stale_host_states = 0;      ///< STATE payloads older than the last one
    std::uint64_t unknown_devices = 0;        ///< events naming no configured device
    std::uint64_t rebirths = 0;               ///< birth sequences after the first of a session
};

class Session {
public:
    /// @p devices: every configured device, in configuration order, all offline until
    /// device_online().
    Session(SessionSettings settings, std::vector<sparkplug::Metric> node_metrics, std::vector<DeviceMetrics> devices);

    /// Before a CONNECT with @p bd_seq (from the BdSeqStore): the will to register.
    [[nodiscard]] Actions connecting(std::uint8_t bd_seq);
    /// CONNACK received: subscriptions, then the births unless a primary host is awaited.
    [[nodiscard]] Actions connected(const Instant& now);
    /// The connection is gone (the broker published the will): data is buffered from now.
    [[nodiscard]] Actions connection_lost();
    /// A message on a STATE topic.
    [[nodiscard]] Actions host_state(std::string_view topic, std::string_view payload, const Instant& now);
    /// @p device answers again: every metric with its current value.
    [[nodiscard]] Actions device_online(std::string_view device, std::vector<sparkplug::Metric> metrics,
                                        const Instant& now);
    /// @p device stopped answering (its comm_loss rule).
    [[nodiscard]] Actions device_offline(std::string_view device, const Instant& now);
    /// Metrics of @p device whose values changed (named as in the birth).
    [[nodiscard]] Actions device_changed(std::string_view device, std::vector<sparkplug::Metric> changed,
                                         const Instant& now);
    /// Node metrics whose values changed.
    [[nodiscard]] Actions node_changed(std::vector<sparkplug::Metric> changed, const Instant& now);
    /// NCMD `Node Control/Rebirth` = true: the whole birth sequence again, same bdSeq.
    [[nodiscard]] Actions rebirth(const Instant& now);
    /// The configuration was reloaded: the new node metrics and devices (with current
    /// values). What changed is born again (docs/sparkplug-session.md, "Reload").
    [[nodiscard]] Actions reload(std::vector<sparkplug::Metric> node_metrics, std::vector<DeviceMetrics> devices,
                                 const Instant& now);
    /// Time passed: data held back by the rate rule that is due now.
    [[nodiscard]] Actions tick(const Instant& now);
    /// Clean stop: NDEATH by the node itself, then DISCONNECT.
    [[nodiscard]] Actions stop(const Instant& now);

    /// When tick() next has something to do; nullopt: nothing held back.
    [[nodiscard]] std::optional<SteadyClock::time_point> next_deadline() const;
    [[nodiscard]] Phase phase() const noexcept { return phase_; }
    /// The bdSeq of the current (or coming) connection; nullopt before connecting().
    [[nodiscard]] std::optional<std::uint8_t> bd_seq() const noexcept { return bd_seq_; }
    [[nodiscard]] const OfflineBuffer& offline_buffer() const noexcept { return buffer_; }
    [[nodiscard]] const SessionCounters& counters() const noexcept { return counters_; }
    [[nodiscard]] const SessionSettings& settings() const noexcept { return settings_; }

private:
    struct Device {
        std::string name;
        std::vector<sparkplug::Metric> metrics;  ///< the birth's definitions with current values
        bool online = false;
        bool born = false;                       ///< DBIRTH published in this session
        std::vector<sparkplug::Metric> pending;  ///< changes held back by min_interval
        std::optional<SteadyClock::time_point> last_data;
    };

    [[nodiscard]] Device* find(std::string_view name);
    [[nodiscard]] bool connected() const noexcept;
    void publish(Actions& out, std::string topic, sparkplug::Payload payload, int qos = 0);
    void subscriptions(Actions& out) const;
    void births(Actions& out, const Instant& now);
    void dbirth(Actions& out, Device& device, const Instant& now);
    void ddeath(Actions& out, Device& device, const Instant& now);
    void ddata(Actions& out, Device& device, std::vector<sparkplug::Metric> metrics, const Instant& now);
    void flush(Actions& out, Device& device, const Instant& now);
    void replay(Actions& out, const Instant& now);
    void buffer(std::string device, std::vector<sparkplug::Metric> metrics, std::uint64_t produced_ms);
    void end_session(Actions& out, const Instant& now, bool next_server);
    void forget_session();
    void lose_session();
    [[nodiscard]] Actions unknown_device(std::string_view name);

    SessionSettings settings_;
    std::vector<sparkplug::Metric> node_metrics_;
    std::vector<Device> devices_;
    Phase phase_ = Phase::disconnected;
    std::optional<std::uint8_t> bd_seq_;
    std::uint8_t seq_ = 0;  ///< the next message's seq
    HostTracker host_;
    OfflineBuffer buffer_;
    SessionCounters counters_;
};

}  // namespace fieldbridge::northbound::sparkplug_session
