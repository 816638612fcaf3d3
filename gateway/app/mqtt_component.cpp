#include "app/mqtt_component.hpp"

#include <utility>

#include <asio/post.hpp>

#include "app/engine_component.hpp"
#include "config/mqtt_uri.hpp"
#include "northbound/mqtt/paho_client.hpp"

namespace fieldbridge::app {

ClientFactory paho_client_factory() {
    return [](asio::io_context& io, const config::MqttConfig& config, const std::string& will_topic) {
        return std::unique_ptr<mqtt::Client>(
            std::make_unique<mqtt::PahoClient>(io, mqtt::paho_options(config, will_topic)));
    };
}

MqttComponent::MqttComponent(asio::io_context& io, std::shared_ptr<spdlog::logger> logger, EngineAccess engine,
                             ClientFactory clients)
    : io_(io), logger_(std::move(logger)), engine_(std::move(engine)), clients_(std::move(clients)) {}

MqttComponent::~MqttComponent() {
    *alive_ = false;
    // Destroyed as the process ends (main's last scope): see leave_to_process_exit().
    if (bridge_) bridge_->leave_client_to_process_exit();
    bridge_.reset();
    // The engine may already be gone (stopped after us): never touch the agents.
    sources_.detach();
}

void MqttComponent::start(daemon::StartContext& context) {
    config_ = context.config();
    build();
}

void MqttComponent::build() {
    if (!config_->mqtt.enabled) {
        logger_->info("MQTT: off (no mqtt section, or enabled: false)");
        return;
    }
    const config::MqttConfig& settings = config_->mqtt;
    // Throws (with the URI) when the client library refuses the configuration: the
    // daemon then refuses to start.
    auto client = clients_(io_, settings, settings.prefix + "/status");
    // The URI was validated with the configuration; an unparsable one only loses the
    // probe. With several brokers the probe of one would not say whether the next
    // attempt's is up: back-off only.
    std::unique_ptr<mqtt::BrokerProbe> probe;
    if (const auto uri = config::parse_mqtt_uri(settings.uris.front()); uri && settings.uris.size() == 1) {
        probe = std::make_unique<mqtt::TcpBrokerProbe>(io_, uri.value->host, uri.value->port);
    }
    bridge_ = std::make_unique<mqtt::Bridge>(io_, mqtt::bridge_settings(settings), std::move(client),
                                             engine_log_sink(logger_), std::move(probe));
    bridge_->set_diag_provider([this] {
        nlohmann::json out = nlohmann::json::object();
        if (engine::Engine* e = engine_ ? engine_() : nullptr) out = engine_diag_.collect(*e, engine::Clock::now());
        for (const auto& provider : diag_) {
            const nlohmann::json extra = provider();
            if (extra.is_object()) out.update(extra);
        }
        return out;
    });
    if (!refresh_pending_) refresh_sources();
    bridge_->start();
    std::string brokers;
    for (const std::string& uri : settings.uris) brokers += (brokers.empty() ? "" : ", ") + uri;
    logger_->info("MQTT: broker {}, client id {}, prefix {}, MQTT {}", brokers, settings.client_id, settings.prefix,
                  config::to_string(settings.version));
}

void MqttComponent::refresh_sources() {
    if (!bridge_) {
        sources_.detach();
        return;
    }
    bridge_->set_sources(sources_.rebuild(engine_ ? engine_() : nullptr));
}

void MqttComponent::stop(daemon::StopContext& context) {
    if (!bridge_) {
        sources_.detach();
        return;
    }
    auto ticket = std::make_shared<daemon::CompletionBarrier::Ticket>(
        context.expect_finished("MQTT offline publication"));
    bridge_->stop([ticket] { ticket->done(); });
    // The engine stops after this component: the sources must not outlive it.
    bridge_->set_sources({});
    sources_.detach();
}

void MqttComponent::retire(std::unique_ptr<mqtt::Bridge> bridge) {
    if (!bridge) return;
    bridge->set_sources({});
    // Kept alive until its `offline` is out (or the stop timeout passed).
    auto holder = std::make_shared<std::unique_ptr<mqtt::Bridge>>(std::move(bridge));
    (*holder)->stop([holder]() mutable { holder->reset(); });
}

void MqttComponent::apply(std::shared_ptr<const config::Config> config) {
    const bool mqtt_changed = !config_ || config_->mqtt != config->mqtt || config_->gateway.id != config->gateway.id;
    const bool engine_rebuilt = !config_ || config_->lines != config->lines;
    config_ = std::move(config);
    if (engine_rebuilt) {
        // The engine component rebuilds its agents on this same reload, maybe
        // already: forget the old ones now, take the new ones once every component
        // has applied the configuration.
        if (bridge_) bridge_->set_sources({});
        sources_.detach();
        refresh_pending_ = true;
    }
    if (mqtt_changed) {
        logger_->info("MQTT: configuration changed; reconnecting");
        retire(std::move(bridge_));
        engine_diag_ = EngineDiag{};
        build();
    }
    if (engine_rebuilt) {
        asio::post(io_, [this, alive = alive_] {
            if (!*alive) return;
            refresh_pending_ = false;
            refresh_sources();
        });
    }
}

void MqttComponent::add_diag(mqtt::DiagProvider provider) { diag_.push_back(std::move(provider)); }

void MqttComponent::add_sources(DeviceSources::Provider provider) {
    sources_.add_provider(std::move(provider));
    if (bridge_ && !refresh_pending_) refresh_sources();
}

std::string MqttComponent::status() const {
    if (!bridge_) return "MQTT off";
    return bridge_->connected() ? "MQTT connected" : "MQTT connecting";
}

}  // namespace fieldbridge::app
