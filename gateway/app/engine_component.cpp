#include "app/engine_component.hpp"

#include "daemon/logging.hpp"

namespace fieldbridge::app {

engine::LogSink engine_log_sink(std::shared_ptr<spdlog::logger> logger) {
    engine::LogSink sink;
    // The sink's threshold is the logger's level at each call (a reload may change
    // it): a message the logger would drop is not even built.
    sink.accepts = [logger](engine::LogLevel level) { return logger->should_log(daemon::to_spdlog_level(level)); };
    sink.write = [logger = std::move(logger)](engine::LogLevel level, std::string_view message) {
        logger->log(daemon::to_spdlog_level(level), "{}", message);
    };
    return sink;
}

EngineComponent::EngineComponent(asio::io_context& io, std::shared_ptr<spdlog::logger> logger,
                                 engine::PortFactory ports)
    : io_(io), logger_(std::move(logger)), ports_(std::move(ports)) {}

EngineComponent::~EngineComponent() {
    if (engine_) engine_->stop();
}

void EngineComponent::notify(engine::Engine* engine) {
    for (const auto& listener : listeners_) listener(engine);
}

void EngineComponent::build(const config::Config& config) {
    engine_ = std::make_unique<engine::Engine>(io_, config, engine_log_sink(logger_), ports_);
    engine_->start();
    logger_->info("line engine: {} line(s), {} device(s); {}", engine_->lines().size(), engine_->devices().size(),
                  engine_->status());
    notify(engine_.get());
}

void EngineComponent::tear_down() {
    if (!engine_) return;
    notify(nullptr);
    engine_->stop();
    engine_.reset();
}

void EngineComponent::start(daemon::StartContext& context) {
    config_ = context.config();
    // READY does not wait for the ports: a missing adapter is retried with back-off
    // and reported, and the rest of the gateway (TCP, MQTT) must come up regardless.
    build(*config_);
}

void EngineComponent::stop(daemon::StopContext& /*context*/) { tear_down(); }

void EngineComponent::apply(std::shared_ptr<const config::Config> config) {
    if (!engine_ || (config_ && config_->lines == config->lines)) {
        config_ = std::move(config);
        return;
    }
    config_ = std::move(config);
    // Only what changed: unchanged lines keep their ports, queues and the transaction
    // in flight (engine/engine.hpp). Listeners re-take their pointers afterwards.
    const auto report = engine_->apply(*config_);
    logger_->info("line engine: reload applied: {}; {}", report.summary(), engine_->status());
    notify(engine_.get());
}

std::string EngineComponent::status() const { return engine_ ? engine_->status() : std::string("engine stopped"); }

}  // namespace fieldbridge::app
