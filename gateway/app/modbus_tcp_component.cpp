#include "app/modbus_tcp_component.hpp"

#include <unistd.h>

#include <map>

namespace fieldbridge::app {

namespace {

std::shared_ptr<const config::ModbusTcpConfig> tcp_config(const std::shared_ptr<const config::Config>& config) {
    // Aliasing constructor: the server's view keeps the whole configuration alive.
    return {config, &config->modbus_tcp};
}

}  // namespace

ModbusTcpComponent::ModbusTcpComponent(asio::io_context& io, std::shared_ptr<spdlog::logger> logger,
                                       EngineComponent& engine,
                                       std::vector<northbound::modbus_tcp::InheritedListener> inherited)
    : io_(io), logger_(std::move(logger)), engine_(engine), inherited_(std::move(inherited)) {
    engine_.on_change([this](engine::Engine* current) {
        if (server_) rebuild_routes(current);
    });
}

ModbusTcpComponent::~ModbusTcpComponent() {
    if (server_) server_->stop();
    stop_upstreams();
    for (const auto& listener : inherited_) ::close(listener.fd);
}

void ModbusTcpComponent::build_upstreams() {
    for (const auto& upstream : config_->upstreams) {
        upstreams_.push_back(
            std::make_unique<northbound::upstream::UpstreamTarget>(io_, upstream, engine_log_sink(logger_)));
        upstreams_.back()->start();
    }
}

void ModbusTcpComponent::stop_upstreams() {
    if (!upstreams_.empty()) {
        for (const auto& listener : upstreams_closing_) listener();
    }
    for (auto& upstream : upstreams_) upstream->stop();
    upstreams_.clear();
}

void ModbusTcpComponent::rebuild_routes(engine::Engine* engine) {
    auto& routes = server_->routes();
    routes.clear();
    // A line the reload left alone keeps its targets: a broadcast target holds the
    // line's budget and its writes in flight (destroying it answers those 0x0A).
    std::map<std::string, LineTargets, std::less<>> next;
    if (engine != nullptr) {
        for (const auto& line : engine->lines()) {
            const std::string& name = line.worker->config().name;
            if (const auto old = line_targets_.find(name); old != line_targets_.end() &&
                                                           old->second.worker == line.worker.get() &&
                                                           old->second.revision == line.revision) {
                next.emplace(name, std::move(old->second));
                continue;
            }
            LineTargets built{line.worker.get(), line.revision, {}, {}};
            std::vector<northbound::LineUnit> units;
            for (const auto& device : engine->devices()) {
                if (device.line != name) continue;
                built.targets.push_back(
                    std::make_unique<northbound::SerialDeviceTarget>(io_, *device.agent, *line.worker));
                built.units.push_back(device.unit_id);
                units.push_back(northbound::LineUnit{device.agent, device.unit_id});
            }
            if (line.broadcast_unit) {
                built.targets.push_back(std::make_unique<northbound::LineBroadcastTarget>(
                    io_, *line.worker, std::move(units),
                    northbound::BroadcastSettings{line.broadcast_ttl, line.broadcast_share}));
                built.units.push_back(*line.broadcast_unit);
            }
            next.emplace(name, std::move(built));
        }
    }
    line_targets_ = std::move(next);
    for (const auto& [name, line] : line_targets_) {
        for (std::size_t t = 0; t < line.targets.size(); ++t) routes.set(line.units[t], *line.targets[t]);
    }
    for (std::size_t u = 0; u < upstreams_.size(); ++u) {
        for (const auto& unit : config_->upstreams.at(u).units) routes.set(unit.unit_id, *upstreams_[u]);
    }
}

void ModbusTcpComponent::start(daemon::StartContext& context) {
    config_ = context.config();
    server_ = std::make_unique<northbound::modbus_tcp::ModbusTcpServer>(io_, tcp_config(config_),
                                                                         engine_log_sink(logger_));
    for (auto& listener : inherited_) server_->adopt(std::move(listener));
    inherited_.clear();
    build_upstreams();
    rebuild_routes(engine_.engine());
    // Binding is synchronous: when start() returns the listeners accept, so READY
    // may go out (a bind failure throws with what to do and the gateway stops).
    server_->start();  // logs each listener
}

void ModbusTcpComponent::stop(daemon::StopContext& /*context*/) {
    if (server_) {
        server_->stop();
        server_->routes().clear();
    }
    line_targets_.clear();
    stop_upstreams();
    server_.reset();
}

void ModbusTcpComponent::prepare(const config::Config& next) {
    if (server_) server_->prepare(next.modbus_tcp);
}

void ModbusTcpComponent::abandon() noexcept {
    if (server_) server_->abandon_prepared();
}

void ModbusTcpComponent::apply(std::shared_ptr<const config::Config> config) {
    const bool upstreams_changed = !config_ || config_->upstreams != config->upstreams;
    config_ = std::move(config);
    if (!server_) return;
    server_->apply(tcp_config(config_));
    if (upstreams_changed) {
        server_->routes().clear();
        stop_upstreams();
        build_upstreams();
    }
    rebuild_routes(engine_.engine());
}

std::string ModbusTcpComponent::status() const { return server_ ? server_->status() : std::string("Modbus TCP off"); }

}  // namespace fieldbridge::app
