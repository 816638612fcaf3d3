#pragma once
/// @file mqtt_client.hpp
/// The seam between the bridge and an MQTT client library (paho_client.hpp is the
/// real one). Every event is delivered on the gateway's loop thread; no call blocks.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

namespace fieldbridge::northbound::mqtt {

struct Message {
    std::string topic;
    std::string payload;
    int qos = 1;
    bool retained = false;
};

/// Callbacks of a client; all run on the loop thread.
struct ClientEvents {
    std::function<void()> connected;
    /// A connect() that did not succeed (the reason as the library gives it).
    std::function<void(const std::string& reason)> connect_failed;
    std::function<void(const std::string& cause)> connection_lost;
    std::function<void(Message message)> message;
    /// The publication @p id (from publish()) was handed over (QoS 0) or acknowledged
    /// (QoS 1/2): @p ok; or failed: !@p ok.
    std::function<void(std::uint64_t id, bool ok)> published;
    /// @p count received messages were dropped because too many waited to be
    /// handled (the client's inbound bound); reported at most once per loop pass.
    std::function<void(std::uint64_t count)> inbound_dropped;
};

class Client {
public:
    Client() = default;
    virtual ~Client() = default;
    Client(const Client&) = delete;
    Client& operator=(const Client&) = delete;

    virtual void set_events(ClientEvents events) = 0;
    /// Starts one connection attempt (with the will set up at construction); the
    /// outcome comes as connected or connect_failed. No automatic reconnect: the
    /// bridge decides when to try again.
    virtual void connect() = 0;
    /// Queues a publication; returns its id, or 0 when it cannot be queued (not
    /// connected, library refused): nothing will be reported for it then.
    [[nodiscard]] virtual std::uint64_t publish(const Message& message) = 0;
    virtual void subscribe(const std::string& filter, int qos) = 0;
    /// Ends a subscription (a device removed by a reload); nothing when not connected.
    virtual void unsubscribe(const std::string& filter) { static_cast<void>(filter); }
    /// The will of the next connect() from now on, replacing the one the client was
    /// made with (the Sparkplug NDEATH carries the connection's bdSeq).
    virtual void set_will(const Message& will) { static_cast<void>(will); }
    /// A clean disconnect (no will), waiting at most @p timeout for what is in flight;
    /// @p done runs on the loop thread afterwards, whatever happened.
    virtual void disconnect(std::chrono::milliseconds timeout, std::function<void()> done) = 0;
    [[nodiscard]] virtual bool connected() const = 0;
    /// The brokers this client can connect to (mqtt.uri as a list), tried in order.
    [[nodiscard]] virtual std::size_t server_count() const { return 1; }
    /// The broker the next connect() goes to: 0 .. server_count() - 1.
    virtual void select_server(std::size_t index) { static_cast<void>(index); }
    /// The process is ending: a client that is not connected may leave its library
    /// state to the process exit instead of tearing it down in its destructor
    /// (PahoClient: paho.mqtt.c's last-client teardown races its worker threads).
    virtual void leave_to_process_exit() noexcept {}
};

}  // namespace fieldbridge::northbound::mqtt
