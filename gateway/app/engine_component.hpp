#pragma once
/// @file engine_component.hpp
/// The line engine as a daemon component: built from the configuration at start; a
/// reload that changes lines or devices applies only the difference
/// (engine::Engine::apply(): unchanged lines keep running), left alone otherwise.
#include <asio/io_context.hpp>
#include <memory>
#include <spdlog/logger.h>
#include <functional>
#include <string>
#include <vector>

#include "daemon/component.hpp"
#include "engine/engine.hpp"

namespace fieldbridge::app {

/// The engine's log sink: messages go to @p logger at the matching level, and are
/// built only when the logger would print them.
[[nodiscard]] engine::LogSink engine_log_sink(std::shared_ptr<spdlog::logger> logger);

class EngineComponent final : public daemon::Component {
public:
    EngineComponent(asio::io_context& io, std::shared_ptr<spdlog::logger> logger,
                    engine::PortFactory ports = engine::posix_port_factory());
    ~EngineComponent() override;

    [[nodiscard]] std::string name() const override { return "line engine"; }
    void start(daemon::StartContext& context) override;
    void stop(daemon::StopContext& context) override;
    void apply(std::shared_ptr<const config::Config> config) override;

    /// Nullptr before start() and after stop().
    [[nodiscard]] engine::Engine* engine() const noexcept { return engine_.get(); }

    /// Called with nullptr just before the engine is destroyed (stop), with the engine
    /// once it runs, and again with it after a reload changed its lines or devices:
    /// whoever holds pointers into the engine (routes, MQTT sources) drops and
    /// re-takes them here (objects a reload replaced stay valid until the next reload).
    using ChangeListener = std::function<void(engine::Engine*)>;
    void on_change(ChangeListener listener) { listeners_.push_back(std::move(listener)); }
    /// For STATUS=.
    [[nodiscard]] std::string status() const;

private:
    void build(const config::Config& config);
    void tear_down();
    void notify(engine::Engine* engine);

    asio::io_context& io_;
    std::shared_ptr<spdlog::logger> logger_;
    engine::PortFactory ports_;
    std::shared_ptr<const config::Config> config_;
    std::unique_ptr<engine::Engine> engine_;
    std::vector<ChangeListener> listeners_;
};

}  // namespace fieldbridge::app
