#pragma once
/// @file edge_node.hpp
/// The Sparkplug B edge node at work (docs/sparkplug.md): the session state machine
/// (sparkplug_session/session.hpp) driven by an MQTT client of its own, the devices
/// (mqtt::DeviceSource, the JSON bridge's view of them) turned into metrics by the
/// catalogue, DCMDs run through the JSON bridge's command parser and runner, node
/// metrics sampled from a probe. It owns the client, the bdSeq store and the
/// session; the caller owns the sources. Loop thread only.
// Standard headers before asio's (see daemon/periodic.hpp).
#include <chrono>
#include <deque>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <asio/io_context.hpp>
#include <asio/steady_timer.hpp>

#include "engine/line_log.hpp"
#include "engine/transaction.hpp"
#include "northbound/mqtt/device_source.hpp"
#include "northbound/mqtt/mqtt_client.hpp"
#include "northbound/mqtt/reconnect_schedule.hpp"
#include "northbound/sparkplug/metric_catalogue.hpp"
#include "northbound/sparkplug_node/dcmd_plan.hpp"
#include "northbound/sparkplug_node/node_metrics.hpp"
#include "northbound/sparkplug_session/bdseq_store.hpp"
#include "northbound/sparkplug_session/session.hpp"

namespace fieldbridge::northbound::sparkplug_node {

struct EdgeNodeSettings {
    sparkplug_session::SessionSettings session;
    std::filesystem::path state_dir;
    /// Smallest change published per field (`mqtt.deadband`); a point's own wins.
    std::map<std::string, double, std::less<>> deadband;
    /// Node metrics are sampled this often; what changed goes out as NDATA.
    std::chrono::milliseconds node_period{5000};
    /// Every device's state is looked at this often too (besides its change reports).
    std::chrono::milliseconds sweep_period{1000};
    mqtt::ReconnectSettings reconnect{std::chrono::seconds{1}, std::chrono::seconds{30}, std::chrono::seconds{1},
                                      std::chrono::milliseconds{800}};
    /// DCMDs being executed at once; more are refused (counted) until one ends.
    std::size_t max_running_commands = 16;
    /// Publications handed to the client and not yet reported published; the rest
    /// wait in order (a replay of the offline buffer is a burst), up to max_waiting.
    std::size_t publish_window = 32;
    std::size_t max_waiting = 25000;
};

/// What the node counts (node metrics and Prometheus).
struct EdgeNodeCounters {
    std::uint64_t commands_accepted = 0;  ///< DCMDs executed to the end (or parameters stored)
    std::uint64_t commands_refused = 0;   ///< DCMD/NCMD refused or failed on the device
    std::uint64_t connections = 0;        ///< sessions established
    std::uint64_t publish_dropped = 0;    ///< publications lost (queue full, or the connection went)
};

/// Takes the node's snapshot (the DCMD counters are filled in by the node).
using NodeProbe = std::function<NodeSnapshot()>;

class EdgeNode {
public:
    EdgeNode(asio::io_context& io, EdgeNodeSettings settings, std::unique_ptr<mqtt::Client> client,
             engine::LogSink log_sink, NodeProbe probe);
    ~EdgeNode();
    EdgeNode(const EdgeNode&) = delete;
    EdgeNode& operator=(const EdgeNode&) = delete;

    /// The devices, in configuration order (a reload replaces them: what changed is
    /// born again). The node never outlives them unless they are replaced first.
    void set_sources(std::vector<std::shared_ptr<mqtt::DeviceSource>> sources);
    /// Connects (bdSeq from the state directory; throws core::Error when it cannot be
    /// written).
    void start();
    /// NDEATH, DISCONNECT, then @p done (also when not connected).
    void stop(std::function<void()> done);

    [[nodiscard]] bool online() const noexcept;
    [[nodiscard]] const EdgeNodeCounters& counters() const noexcept { return counters_; }
    [[nodiscard]] const sparkplug_session::Session& session() const noexcept { return session_; }
    void leave_client_to_process_exit() noexcept { client_->leave_to_process_exit(); }

private:
    struct Device {
        std::shared_ptr<mqtt::DeviceSource> source;
        bool online = false;
        engine::DecodedState published;  ///< the values the host has
        StoredArguments arguments;       ///< Commands/<op>/<field> set by DCMDs
        bool dirty = false;
    };

    [[nodiscard]] sparkplug_session::Instant now() const;
    [[nodiscard]] sparkplug::DeviceShape shape_of(const mqtt::DeviceSource& source,
                                                  const engine::DecodedState& state) const;
    [[nodiscard]] std::vector<sparkplug::Metric> birth_metrics(const Device& device,
                                                               const engine::DecodedState& state,
                                                               std::uint64_t now_ms) const;
    [[nodiscard]] std::vector<sparkplug::Metric> current_node_metrics(std::uint64_t now_ms);
    void listen(std::size_t index);
    void refresh(Device& device);
    void refresh_dirty();
    void sweep();
    void sample_node();
    void arm_tick();
    void apply(const sparkplug_session::Actions& actions);
    void connect_attempt();
    void send(mqtt::Message message);
    void drain();
    void disconnect(bool walk);
    void next_server();
    void on_message(const mqtt::Message& message);
    void on_ncmd(const std::string& payload);
    void on_dcmd(Device& device, const std::string& payload);
    void refuse(const std::string& what, const std::string& why);
    void log(core::LogLevel level, const std::string& text) const;

    asio::io_context& io_;
    EdgeNodeSettings settings_;
    std::unique_ptr<mqtt::Client> client_;
    engine::LogSink log_;
    NodeProbe probe_;
    sparkplug_session::BdSeqStore store_;
    sparkplug::MetricCatalogue catalogue_;
    sparkplug_session::Session session_;
    std::vector<Device> devices_;
    std::map<std::string, std::uint64_t, std::less<>> node_aliases_;
    std::vector<sparkplug::Metric> node_published_;
    mqtt::ReconnectSchedule reconnect_;
    asio::steady_timer sweep_timer_;
    asio::steady_timer tick_timer_;
    asio::steady_timer retry_timer_;  ///< a refused publication, with none in flight to wake the drain
    std::optional<engine::TimePoint> tick_due_;
    engine::TimePoint next_node_sample_{};
    std::size_t server_ = 0;
    std::size_t running_commands_ = 0;
    std::deque<mqtt::Message> waiting_;  ///< publications in order, behind the window
    std::size_t in_flight_ = 0;
    std::optional<bool> disconnect_after_;  ///< a Disconnect (its walk) waiting for waiting_ to drain
    bool refresh_posted_ = false;
    bool started_ = false;
    bool stopping_ = false;
    std::function<void()> stop_done_;
    EdgeNodeCounters counters_;
    std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace fieldbridge::northbound::sparkplug_node
