#pragma once
/// @file mqtt_component.hpp
/// The MQTT bridge as a daemon component. Off when the configuration has no `mqtt`
/// section (or `enabled: false`). Its devices are the serial devices of the line
/// engine (found through @p engine at start and after a reload that rebuilt the
/// engine); its diag carries the engine's counters and whatever extra sections are
/// added (Modbus TCP clients).
///
/// Register it AFTER the engine component: it is then stopped first, so `offline`
/// is published while the lines still run. READY does not wait for the broker (a
/// broker outage must not keep Modbus TCP from starting).
// Standard headers before asio's (see daemon/periodic.hpp).
#include <functional>
#include <memory>
#include <spdlog/logger.h>
#include <string>
#include <vector>

#include <asio/io_context.hpp>

#include "app/device_sources.hpp"
#include "app/engine_diag.hpp"
#include "daemon/component.hpp"
#include "engine/engine.hpp"
#include "northbound/mqtt/agent_source.hpp"
#include "northbound/mqtt/mqtt_bridge.hpp"

namespace fieldbridge::app {

namespace mqtt = northbound::mqtt;

/// Makes the client of a bridge (tests may inject another).
using ClientFactory =
    std::function<std::unique_ptr<mqtt::Client>(asio::io_context&, const config::MqttConfig&,
                                                 const std::string& will_topic)>;
[[nodiscard]] ClientFactory paho_client_factory();

class MqttComponent final : public daemon::Component {
public:
    using EngineAccess = std::function<engine::Engine*()>;

    MqttComponent(asio::io_context& io, std::shared_ptr<spdlog::logger> logger, EngineAccess engine,
                  ClientFactory clients = paho_client_factory());
    ~MqttComponent() override;

    [[nodiscard]] std::string name() const override { return "MQTT bridge"; }
    void start(daemon::StartContext& context) override;
    void stop(daemon::StopContext& context) override;
    void apply(std::shared_ptr<const config::Config> config) override;

    /// Merged into `<prefix>/diag` (e.g. {"modbus_tcp": {...}}).
    void add_diag(mqtt::DiagProvider provider);
    /// More devices (the R6 units of the upstream pass-through: make_r6_sources()),
    /// asked at start and whenever the sources are rebuilt. Their owner detaches them
    /// before the objects behind them go.
    void add_sources(DeviceSources::Provider provider);
    /// Nullptr when MQTT is off.
    [[nodiscard]] const mqtt::Bridge* bridge() const noexcept { return bridge_.get(); }
    /// For STATUS=: "MQTT connected" / "MQTT connecting" / "MQTT off".
    [[nodiscard]] std::string status() const;

private:
    void build();
    void refresh_sources();
    void retire(std::unique_ptr<mqtt::Bridge> bridge);

    asio::io_context& io_;
    std::shared_ptr<spdlog::logger> logger_;
    EngineAccess engine_;
    ClientFactory clients_;
    std::shared_ptr<const config::Config> config_;
    std::unique_ptr<mqtt::Bridge> bridge_;
    DeviceSources sources_{io_, /*notices=*/true};
    std::vector<mqtt::DiagProvider> diag_;
    EngineDiag engine_diag_;
    bool refresh_pending_ = false;  ///< the engine is being rebuilt: its agents come later
    /// Set to false when the component goes: posted refreshes do nothing then.
    std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace fieldbridge::app
