#include "northbound/mqtt/paho_client.hpp"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <map>
#include <mutex>
#include <stdexcept>
#include <utility>

#include <asio/post.hpp>
#include <asio/steady_timer.hpp>
#include <mqtt/async_client.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "core/error.hpp"
#include "northbound/mqtt/inbound_gate.hpp"
#include "northbound/mqtt/tls_advice.hpp"

namespace fieldbridge::northbound::mqtt {

namespace {

[[nodiscard]] void* context_of(std::uint64_t id) noexcept {
    return reinterpret_cast<void*>(static_cast<std::uintptr_t>(id));
}
/// What the loop needs of a Paho token (tokens belong to Paho and do not copy).
struct TokenInfo {
    std::uint64_t id = 0;
    std::string reason;
};

[[nodiscard]] TokenInfo info_of(const ::mqtt::token& token) {
    TokenInfo info;
    info.id = static_cast<std::uint64_t>(reinterpret_cast<std::uintptr_t>(token.get_user_context()));
    info.reason = ::mqtt::exception::printable_error(token.get_return_code(), token.get_reason_code());
    return info;
}

/// After an oversize message: how long the loop waits before giving memory back
/// (Paho frees its copies of the message when the message callback has returned).
constexpr std::chrono::milliseconds trim_delay{200};

/// Returns the free pages of every malloc arena to the system. Paho reads a message
/// whole, in two or three copies on its own thread's arena; glibc keeps what a large
/// free leaves below its mmap threshold, so one big message would otherwise stay in
/// the process's resident set.
void release_free_memory() noexcept {
#if defined(__GLIBC__)
    ::malloc_trim(0);
#endif
}

}  // namespace

PahoOptions paho_options(const config::MqttConfig& config, const std::string& will_topic) {
    PahoOptions o = connection_options(config.uris, config);
    o.version = config.version;
    o.clean_session = config.clean_session;
    o.will = Message{will_topic, "offline", config.qos, true};
    o.max_inbound_messages = config.max_queued_commands;
    o.max_inbound_bytes = config.max_queued_command_bytes;
    o.max_payload_bytes = config.max_command_bytes;
    if (config.version == config::MqttVersion::v5) {
        o.max_packet_bytes = static_cast<std::uint32_t>(config.max_command_bytes) + packet_headroom_bytes;
    }
    return o;
}

/// Everything Paho's threads may reach. Paho callbacks only call post(); the
/// posted functions run on the loop and only while the client exists.
class PahoClient::Core {
public:
    /// An action listener that posts its outcome to the loop.
    class Listener final : public ::mqtt::iaction_listener {
    public:
        using Handler = std::function<void(Core&, const TokenInfo&, bool ok)>;
        Listener(Core& core, Handler handler) : core_(core), handler_(std::move(handler)) {}

    private:
        void on_success(const ::mqtt::token& token) override { relay(token, true); }
        void on_failure(const ::mqtt::token& token) override { relay(token, false); }
        void relay(const ::mqtt::token& token, bool ok) {
            // What the loop needs is copied here: the token belongs to Paho.
            std::function<void(Core&)> event;
            try {
                event = [handler = handler_, copied = info_of(token), ok](Core& core) { handler(core, copied, ok); };
            } catch (...) {
                return;
            }
            core_.post(std::move(event));
        }
        Core& core_;
        Handler handler_;
    };

    Core(asio::io_context& io, PahoOptions options)
        : io_(io), options_(std::move(options)), inbound_(options_.max_inbound_messages, options_.max_inbound_bytes) {}
    Core(const Core&) = delete;
    Core& operator=(const Core&) = delete;
    ~Core() = default;

    /// From any thread: runs @p event on the loop unless the client is gone by then.
    void post(std::function<void(Core&)> event) noexcept {
        try {
            const std::lock_guard lock(mutex_);
            if (!accepting_) return;
            asio::post(io_, [alive = alive_, this, event = std::move(event)] {
                if (*alive) event(*this);
            });
        } catch (...) {
            // A Paho thread must never see an exception (allocation failure here).
        }
    }

    /// Loop thread: no more events, and none of those already posted will run.
    void close() noexcept {
        {
            const std::lock_guard lock(mutex_);
            accepting_ = false;
        }
        *alive_ = false;
    }

    /// Paho thread: a message over the inbound bound was dropped; the loop hears of
    /// it once, however many follow before it runs.
    void report_drop() noexcept {
        if (drop_report_pending_.exchange(true)) return;
        post([](Core& c) {
            c.drop_report_pending_ = false;
            const std::uint64_t count = c.inbound_.take_unreported();
            if (count > 0 && c.events_.inbound_dropped) c.events_.inbound_dropped(count);
        });
    }

    /// Paho thread: a payload above max_payload_bytes was read whole (MQTT 3.1.1, or
    /// a broker that ignores the Maximum Packet Size). The loop gives the memory back
    /// once Paho has freed it; one trim for a burst of them.
    void trim_after_oversize() noexcept {
        if (trim_pending_.exchange(true)) return;
        post([](Core& c) {
            c.trim_timer_.expires_after(trim_delay);
            c.trim_timer_.async_wait([alive = c.alive_, &c](const asio::error_code& error) {
                if (error || !*alive) return;  // the Core may be gone: touch nothing
                c.trim_pending_ = false;
                release_free_memory();
            });
        });
    }

    asio::io_context& io_;
    PahoOptions options_;
    InboundGate inbound_;
    std::atomic<bool> trim_pending_{false};
    asio::steady_timer trim_timer_{io_};
    std::atomic<bool> drop_report_pending_{false};
    std::unique_ptr<::mqtt::async_client> client_;
    ClientEvents events_;
    bool connected_ = false;
    std::uint64_t next_id_ = 1;
    std::map<std::uint64_t, std::function<void()>> disconnects_;

    Listener connect_listener_{*this, [](Core& core, const TokenInfo& token, bool ok) {
                                   core.connected_ = ok;
                                   if (ok) {
                                       if (core.events_.connected) core.events_.connected();
                                   } else if (core.events_.connect_failed) {
                                       core.events_.connect_failed(
                                           core.options_.tls
                                               ? token.reason + "; " + tls_failure_advice(core.options_.tls_files)
                                               : token.reason);
                                   }
                               }};

    Listener publish_listener_{*this, [](Core& core, const TokenInfo& token, bool ok) {
                                   if (core.events_.published) core.events_.published(token.id, ok);
                               }};
    Listener subscribe_listener_{*this, [](Core&, const TokenInfo&, bool) {}};
    Listener disconnect_listener_{*this, [](Core& core, const TokenInfo& token, bool) {
                                      core.connected_ = false;
                                      const auto it = core.disconnects_.find(token.id);
                                      if (it != core.disconnects_.end()) {
                                          auto done = std::move(it->second);
                                          core.disconnects_.erase(it);
                                          if (done) done();
                                      }
                                  }};

private:
    std::mutex mutex_;
    bool accepting_ = true;
    // Shared with the posted handlers: they may run after the Core is gone.
    std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

PahoClient::PahoClient(asio::io_context& io, PahoOptions options)
    : core_(std::make_shared<Core>(io, std::move(options))) {
    const PahoOptions& o = core_->options_;
    const int version = o.version == config::MqttVersion::v5 ? MQTTVERSION_5 : MQTTVERSION_3_1_1;
    try {
        // No persistence and no offline buffer: state is republished on reconnect.
        core_->client_ = std::make_unique<::mqtt::async_client>(o.uri, o.client_id, ::mqtt::create_options(version));
    } catch (const std::exception& e) {
        throw core::Error(std::string{"cannot create a client: "} + e.what(), "MQTT broker " + o.uri,
                          "check mqtt.uri in the configuration");
    }
    Core* core = core_.get();
    core_->client_->set_connection_lost_handler([core](const std::string& cause) {
        core->post([cause](Core& c) {
            c.connected_ = false;
            if (c.events_.connection_lost) c.events_.connection_lost(cause.empty() ? "connection lost" : cause);
        });
    });
    core_->client_->set_message_callback([core](::mqtt::const_message_ptr message) {
        if (!message) return;
        std::string topic;
        std::string payload;
        try {
            topic = message->get_topic();
            // An oversized payload is cut: the bridge refuses it by its size alone.
            const auto& whole = message->get_payload();
            payload.assign(whole.data(), std::min(whole.size(), core->options_.max_payload_bytes + 1));
            if (whole.size() > core->options_.max_payload_bytes) core->trim_after_oversize();
        } catch (...) {
            return;
        }
        const std::size_t bytes = topic.size() + payload.size();
        if (!core->inbound_.admit(bytes)) {
            core->report_drop();
            return;
        }
        const int qos = message->get_qos();
        const bool retained = message->is_retained();
        core->post([m = Message{std::move(topic), std::move(payload), qos, retained}, bytes](Core& c) mutable {
            c.inbound_.release(bytes);
            if (c.events_.message) c.events_.message(std::move(m));
        });
    });
}

PahoClient::~PahoClient() {
    core_->close();
    try {
        core_->client_->disable_callbacks();
        if (core_->client_->is_connected()) {
            // Not a clean stop (that is disconnect()): leave without blocking the loop
            // for long; the broker publishes the will.
            core_->client_->disconnect(0)->wait_for(std::chrono::milliseconds{100});
        }
    } catch (...) {
        // Tearing down: Paho may refuse when the connection is already gone.
    }
    if (leave_to_exit_ && !core_->connected_) {
        // The process is ending and the loop sees no connection (callbacks off).
        // Destroying Paho's last client runs MQTTAsync_terminate, which races the
        // library's detached worker threads as they stop (paho.mqtt.c#1669): one TLS
        // test run saw the send thread fault after "stopped". The handle stays
        // reachable from Paho's own client list until exit; the kernel takes the rest.
        //
        // A connect may still be in flight (the node walked to its next server just
        // before SIGTERM): Paho then calls connect_listener_ when the CONNACK or the
        // timeout comes, and its token keeps only a raw pointer to it. So the Core
        // (every listener) lives as long as the handle: the handle holds it in a
        // handler Paho calls at most before a reconnect (never: no automatic
        // reconnect), and a late listener call finds the Core closed and posts nothing.
        auto* leaked = core_->client_.release();
        try {
            leaked->set_update_connection_handler([anchor = core_](::mqtt::connect_data&) {
                static_cast<void>(anchor);
                return false;
            });
        } catch (...) {
            // Paho refused the handler (out of memory): keep the Core by leaking it.
            static_cast<void>(new std::shared_ptr<Core>(core_));
        }
        return;
    }
    core_->client_.reset();
}

void PahoClient::set_events(ClientEvents events) { core_->events_ = std::move(events); }

void PahoClient::connect() {
    const PahoOptions& o = core_->options_;
    try {
        ::mqtt::connect_options options;
        options.set_mqtt_version(o.version == config::MqttVersion::v5 ? MQTTVERSION_5 : MQTTVERSION_3_1_1);
        options.set_keep_alive_interval(static_cast<int>(o.keep_alive.count()));
        if (o.version == config::MqttVersion::v5) {
            options.set_clean_start(o.clean_session);
        } else {
            options.set_clean_session(o.clean_session);
        }
        if (o.version == config::MqttVersion::v5 && o.max_packet_bytes > 0) {
            ::mqtt::properties properties;
            properties.add(::mqtt::property(::mqtt::property::MAXIMUM_PACKET_SIZE,
                                            static_cast<int32_t>(o.max_packet_bytes)));
            options.set_properties(std::move(properties));
        }
        options.set_connect_timeout(static_cast<int>(o.connect_timeout.count()));
        options.set_automatic_reconnect(false);
        options.set_max_inflight(o.max_inflight);
        if (!o.username.empty()) options.set_user_name(o.username);
        if (!o.password.empty()) options.set_password(o.password);
        options.set_will(::mqtt::will_options(o.will.topic, o.will.payload, o.will.qos, o.will.retained));
        if (o.servers.size() > 1 && server_ < o.servers.size()) {
            // A list: this attempt goes to the chosen broker instead of the URI the
            // client was created with (every broker of the list has the same
            // TLS-ness: the configuration checks it). One broker: as created.
            options.set_servers(::mqtt::string_collection::create(o.servers[server_]));
        }
        if (o.tls) {
            ::mqtt::ssl_options ssl;
            if (!o.tls_files.ca_file.empty()) ssl.set_trust_store(o.tls_files.ca_file);
            if (!o.tls_files.cert_file.empty()) ssl.set_key_store(o.tls_files.cert_file);
            if (!o.tls_files.key_file.empty()) ssl.set_private_key(o.tls_files.key_file);
            ssl.set_enable_server_cert_auth(o.tls_files.verify);
            ssl.set_verify(o.tls_files.verify);
            // No ssl_options::set_error_handler(): with Debian 12's Paho it crashes
            // (a null callback on Paho's thread, seen under ASan); tls_failure_advice()
            // names the settings instead.
            options.set_ssl(std::move(ssl));
        }
        core_->client_->connect(options, nullptr, core_->connect_listener_);
    } catch (const std::exception& e) {
        core_->post([reason = std::string(e.what())](Core& c) {
            if (c.events_.connect_failed) c.events_.connect_failed(reason);
        });
    }
}

std::size_t PahoClient::server_count() const {
    return std::max<std::size_t>(1, core_->options_.servers.size());
}

void PahoClient::select_server(std::size_t index) { server_ = index < server_count() ? index : 0; }

std::uint64_t PahoClient::publish(const Message& message) {
    if (!core_->connected_) return 0;
    const std::uint64_t id = core_->next_id_++;
    try {
        auto msg = ::mqtt::make_message(message.topic, message.payload, message.qos, message.retained);
        core_->client_->publish(msg, context_of(id), core_->publish_listener_);
        return id;
    } catch (const std::exception&) {
        // Not connected any more, or Paho's queue refused it: the bridge republishes
        // state on the next connection.
        return 0;
    }
}

void PahoClient::subscribe(const std::string& filter, int qos) {
    try {
        // MQTT 5: retain-as-published, so a command published with the retain flag
        // keeps it on live delivery too and the bridge refuses it (3.1.1 clears the
        // flag on live delivery: such a command runs once, docs/mqtt.md).
        const ::mqtt::subscribe_options options(
            false, core_->options_.version == config::MqttVersion::v5 ? ::mqtt::subscribe_options::RETAIN_AS_PUBLISHED
                                                                      : ::mqtt::subscribe_options::NO_RETAIN_AS_PUBLISHED);
        core_->client_->subscribe(filter, qos, nullptr, core_->subscribe_listener_, options);
    } catch (const std::exception&) {
        // Lost the connection meanwhile: subscribed again on the next one.
    }
}

void PahoClient::unsubscribe(const std::string& filter) {
    try {
        if (core_->client_->is_connected()) core_->client_->unsubscribe(filter);
    } catch (const std::exception&) {
        // Lost the connection meanwhile: the next session does not subscribe it.
    }
}

void PahoClient::set_will(const Message& will) { core_->options_.will = will; }

void PahoClient::disconnect(std::chrono::milliseconds timeout, std::function<void()> done) {
    const std::uint64_t id = core_->next_id_++;
    try {
        if (core_->client_->is_connected()) {
            core_->disconnects_[id] = std::move(done);
            core_->client_->disconnect(static_cast<int>(timeout.count()), context_of(id), core_->disconnect_listener_);
            return;
        }
    } catch (const std::exception&) {
        done = std::move(core_->disconnects_[id]);
        core_->disconnects_.erase(id);
    }
    core_->connected_ = false;
    core_->post([done = std::move(done)](Core&) {
        if (done) done();
    });
}

bool PahoClient::connected() const { return core_->connected_; }

}  // namespace fieldbridge::northbound::mqtt
