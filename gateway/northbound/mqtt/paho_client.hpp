#pragma once
/// @file paho_client.hpp
/// The Client seam over Eclipse Paho MQTT C++ (mqtt::async_client). Paho runs its
/// own threads and calls back on them (paho.mqtt.cpp include/mqtt/async_client.h):
/// every callback here only posts the event to the gateway's io_context, inside a
/// try/catch wall, and does nothing once the client is being destroyed. No automatic
/// reconnect and no offline buffering in Paho: the bridge owns both.
// Standard headers before asio's (see daemon/periodic.hpp).
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <asio/io_context.hpp>

#include "config/config.hpp"
#include "northbound/mqtt/mqtt_client.hpp"

namespace fieldbridge::northbound::mqtt {

struct PahoOptions {
    std::string uri = "tcp://127.0.0.1:1883";  ///< the client is created with this one
    /// The brokers to walk (mqtt.uri as a list; uri is the first); empty: uri only.
    /// Each connection attempt goes to the one select_server() chose.
    std::vector<std::string> servers;
    std::string client_id;
    std::string username;  ///< empty: none
    std::string password;  ///< empty: none
    bool tls = false;      ///< ssl:// or wss://
    config::MqttTlsConfig tls_files;
    config::MqttVersion version = config::MqttVersion::v3_1_1;
    std::chrono::seconds keep_alive{30};
    bool clean_session = true;
    Message will;  ///< `<prefix>/status` = "offline", retained
    std::chrono::seconds connect_timeout{10};
    /// QoS 1/2 publications awaiting their acknowledgement (Paho's maxInflight).
    int max_inflight = 64;
    /// Received messages waiting for the loop: beyond either bound they are dropped.
    std::size_t max_inbound_messages = 64;
    std::size_t max_inbound_bytes = 1024 * 1024;
    /// A payload is kept up to this many bytes plus one (enough for the bridge to
    /// see it is too large without holding all of it).
    std::size_t max_payload_bytes = 16 * 1024;
    /// MQTT 5: the Maximum Packet Size sent on CONNECT; the broker sends no larger
    /// packet (it drops such a message for this client), so a huge publish on a cmd
    /// topic never reaches the gateway's memory. 0: none (and never with 3.1.1,
    /// which has no such property: there only the broker's own limit helps).
    std::uint32_t max_packet_bytes = 0;
};

/// Headroom of the Maximum Packet Size over mqtt.max_command_bytes: the longest topic
/// MQTT allows (65535 bytes and its length), the fixed header, packet identifier and
/// properties. A payload up to max_command_bytes always gets through, and one a little
/// larger still gets its `too_large` result.
inline constexpr std::uint32_t packet_headroom_bytes = 64 * 1024 + 1024;

/// What every broker connection of the gateway takes from its config section
/// (config::MqttConfig, config::SparkplugConfig): the brokers to walk (@p servers, the
/// first one the client's), client id, credentials, TLS and keep-alive. The rest
/// (version, session, will, inbound bounds) is each northbound's own.
template <typename Section>
[[nodiscard]] PahoOptions connection_options(const std::vector<std::string>& servers, const Section& section) {
    PahoOptions o;
    o.uri = servers.front();
    o.servers = servers;
    o.client_id = section.client_id;
    o.username = section.username;
    o.password = section.password;
    o.tls = section.uses_tls();
    o.tls_files = section.tls;
    o.keep_alive = std::chrono::duration_cast<std::chrono::seconds>(section.keep_alive);
    return o;
}

/// The options of @p config with the will on @p will_topic.
[[nodiscard]] PahoOptions paho_options(const config::MqttConfig& config, const std::string& will_topic);

class PahoClient final : public Client {
public:
    /// Throws std::runtime_error naming the URI when Paho refuses it.
    PahoClient(asio::io_context& io, PahoOptions options);
    ~PahoClient() override;
    void leave_to_process_exit() noexcept override { leave_to_exit_ = true; }

    void set_events(ClientEvents events) override;
    void connect() override;
    [[nodiscard]] std::uint64_t publish(const Message& message) override;
    void subscribe(const std::string& filter, int qos) override;
    void unsubscribe(const std::string& filter) override;
    void set_will(const Message& will) override;
    void disconnect(std::chrono::milliseconds timeout, std::function<void()> done) override;
    [[nodiscard]] bool connected() const override;
    [[nodiscard]] std::size_t server_count() const override;
    void select_server(std::size_t index) override;

    class Core;

private:
    std::shared_ptr<Core> core_;
    bool leave_to_exit_ = false;
    std::size_t server_ = 0;
};

}  // namespace fieldbridge::northbound::mqtt
