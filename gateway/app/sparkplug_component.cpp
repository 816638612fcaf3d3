#include "app/sparkplug_component.hpp"

#include <utility>

#include <asio/post.hpp>

#include "app/engine_component.hpp"

namespace fieldbridge::app {

namespace mqtt = northbound::mqtt;

mqtt::PahoOptions sparkplug_paho_options(const config::SparkplugConfig& config) {
    mqtt::PahoOptions o = mqtt::connection_options(config.servers, config);
    // Sparkplug 3.0: MQTT 3.1.1 with a clean session (tck-id-principles-persistence-clean-session-311).
    o.version = config::MqttVersion::v3_1_1;
    o.clean_session = true;
    // The real will (NDEATH with the connection's bdSeq) is set before every CONNECT.
    o.will = mqtt::Message{};
    // A DCMD is small (sparkplug::CommandLimits): larger payloads are cut and refused.
    o.max_payload_bytes = northbound::sparkplug::CommandLimits{}.max_bytes;
    o.max_inbound_messages = 64;
    o.max_inbound_bytes = 1024 * 1024;
    return o;
}

SparkplugComponent::SparkplugComponent(asio::io_context& io, std::shared_ptr<spdlog::logger> logger,
                                       EngineAccess engine, std::string version, ProbeExtras extras)
    : io_(io),
      logger_(std::move(logger)),
      engine_(std::move(engine)),
      version_(std::move(version)),
      extras_(std::move(extras)) {}

SparkplugComponent::~SparkplugComponent() {
    *alive_ = false;
    if (node_) node_->leave_client_to_process_exit();
    node_.reset();
    sources_.detach();
}

void SparkplugComponent::start(daemon::StartContext& context) {
    config_ = context.config();
    build();
}

void SparkplugComponent::build() {
    if (!config_->sparkplug) {
        logger_->info("Sparkplug: off (no sparkplug section)");
        return;
    }
    const config::SparkplugConfig& c = *config_->sparkplug;
    sparkplug_node::EdgeNodeSettings settings;
    settings.session.node = {c.group_id, c.edge_node_id};
    settings.session.primary_host_id = c.primary_host_id;
    settings.session.aliases = c.aliases;
    settings.session.min_interval = config_->mqtt.min_interval;
    settings.session.offline_max_messages = c.offline_buffer.max_messages;
    settings.session.offline_max_bytes = c.offline_buffer.max_bytes;
    settings.state_dir = c.state_dir;
    for (const auto& [field, band] : config_->mqtt.deadband) settings.deadband.emplace(field, band);
    // Throws (with the URI) when Paho refuses the configuration: the daemon then refuses to start.
    auto client = std::make_unique<mqtt::PahoClient>(io_, sparkplug_paho_options(c));
    node_ = std::make_unique<sparkplug_node::EdgeNode>(io_, std::move(settings), std::move(client),
                                                       engine_log_sink(logger_), [this] { return snapshot(); });
    if (!refresh_pending_) refresh_sources();
    node_->start();
    std::string servers;
    for (const std::string& uri : c.servers) servers += (servers.empty() ? "" : ", ") + uri;
    logger_->info("Sparkplug: edge node {}/{} on {}, client id {}, primary host {}, bdSeq kept in {}", c.group_id,
                  c.edge_node_id, servers, c.client_id, c.primary_host_id.empty() ? "none" : c.primary_host_id,
                  c.state_dir);
}

sparkplug_node::NodeSnapshot SparkplugComponent::snapshot() {
    sparkplug_node::NodeSnapshot s;
    s.version = version_;
    if (engine::Engine* e = engine_ ? engine_() : nullptr) {
        const engine::TimePoint now = engine::Clock::now();
        for (const engine::LineEntry& line : e->lines()) {
            const engine::LineWorker& worker = *line.worker;
            const engine::LineCounters& c = worker.master().counters();
            sparkplug_node::LineSnapshot out;
            out.name = worker.config().name;
            out.up = worker.line_up();
            out.requests = c.requests;
            out.timeouts = c.timeouts;
            LineSample& previous = samples_[out.name];
            const double wall = std::chrono::duration<double>(now - previous.at).count();
            if (previous.at != engine::TimePoint{} && wall > 0 && c.requests >= previous.requests &&
                c.busy_time >= previous.busy) {
                out.transactions_per_second = static_cast<double>(c.requests - previous.requests) / wall;
                out.utilisation_pct = 100.0 * std::chrono::duration<double>(c.busy_time - previous.busy).count() / wall;
            }
            previous = LineSample{c.requests, c.busy_time, now};
            s.lines.push_back(std::move(out));
        }
    }
    if (extras_) extras_(s);
    return s;
}

void SparkplugComponent::refresh_sources() {
    if (!node_) {
        sources_.detach();
        return;
    }
    node_->set_sources(sources_.rebuild(engine_ ? engine_() : nullptr));
}

void SparkplugComponent::add_sources(DeviceSources::Provider provider) {
    sources_.add_provider(std::move(provider));
    if (node_ && !refresh_pending_) refresh_sources();
}

void SparkplugComponent::stop(daemon::StopContext& context) {
    if (!node_) {
        sources_.detach();
        return;
    }
    auto ticket = std::make_shared<daemon::CompletionBarrier::Ticket>(context.expect_finished("Sparkplug NDEATH"));
    node_->stop([ticket] { ticket->done(); });
    // The engine stops after this component: the sources must not outlive it.
    sources_.detach();
}

void SparkplugComponent::retire(std::unique_ptr<sparkplug_node::EdgeNode> node) {
    if (!node) return;
    // Kept alive until its NDEATH is out (or the disconnect timed out).
    auto holder = std::make_shared<std::unique_ptr<sparkplug_node::EdgeNode>>(std::move(node));
    // Destroyed on a later turn of the loop, never inside its own callback.
    (*holder)->stop([holder, &io = io_] { asio::post(io, [holder] { holder->reset(); }); });
}

void SparkplugComponent::apply(std::shared_ptr<const config::Config> config) {
    const bool node_changed = !config_ || config_->sparkplug != config->sparkplug ||
                              config_->gateway.id != config->gateway.id ||
                              config_->mqtt.min_interval != config->mqtt.min_interval ||
                              config_->mqtt.deadband != config->mqtt.deadband;
    const bool engine_rebuilt = !config_ || config_->lines != config->lines;
    config_ = std::move(config);
    if (engine_rebuilt) {
        // The engine component rebuilds its agents on this same reload: forget the old
        // ones now, take the new ones once every component has applied the configuration.
        sources_.detach();
        refresh_pending_ = true;
    }
    if (node_changed) {
        logger_->info("Sparkplug: configuration changed; NDEATH and a new session");
        retire(std::move(node_));
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

std::string SparkplugComponent::status() const {
    if (!node_) return "";
    return node_->online() ? "Sparkplug online" : "Sparkplug connecting";
}

}  // namespace fieldbridge::app
