#pragma once
/// @file sparkplug_component.hpp
/// The Sparkplug B edge node as a daemon component (docs/sparkplug.md): off without a
/// `sparkplug` section. Its devices are the serial devices of the line engine, found
/// through @p engine at start and after a reload that rebuilt the engine (sources of
/// its own, beside the JSON bridge's). Its node metrics come from a probe the caller
/// gives (lines, upstreams, the JSON bridge). A changed `sparkplug` section (or
/// gateway id) ends the session with NDEATH and starts a new one.
///
/// Register it after the engine component: it is then stopped first, so its NDEATH
/// goes out while the lines still run. READY does not wait for the broker.
// Standard headers before asio's (see daemon/periodic.hpp).
#include <functional>
#include <map>
#include <memory>
#include <spdlog/logger.h>
#include <string>
#include <vector>

#include <asio/io_context.hpp>

#include "app/device_sources.hpp"
#include "daemon/component.hpp"
#include "engine/engine.hpp"
#include "northbound/mqtt/agent_source.hpp"
#include "northbound/mqtt/paho_client.hpp"
#include "northbound/sparkplug_node/edge_node.hpp"

namespace fieldbridge::app {

namespace sparkplug_node = northbound::sparkplug_node;

/// The Paho options of the edge node's own connection (its will is set per connection).
[[nodiscard]] northbound::mqtt::PahoOptions sparkplug_paho_options(const config::SparkplugConfig& config);

class SparkplugComponent final : public daemon::Component {
public:
    using EngineAccess = std::function<engine::Engine*()>;
    /// The parts of the node's snapshot outside the engine (upstream links, JSON bridge).
    using ProbeExtras = std::function<void(sparkplug_node::NodeSnapshot&)>;

    SparkplugComponent(asio::io_context& io, std::shared_ptr<spdlog::logger> logger, EngineAccess engine,
                       std::string version, ProbeExtras extras);
    ~SparkplugComponent() override;

    [[nodiscard]] std::string name() const override { return "Sparkplug B edge node"; }
    void start(daemon::StartContext& context) override;
    void stop(daemon::StopContext& context) override;
    void apply(std::shared_ptr<const config::Config> config) override;

    /// More devices (the R6 units of the upstream pass-through, sources of their own:
    /// make_r6_sources() with a copy for this node), asked at start and whenever the
    /// sources are rebuilt. Their owner detaches them before the objects behind them go.
    void add_sources(DeviceSources::Provider provider);
    /// Nullptr when Sparkplug is off.
    [[nodiscard]] const sparkplug_node::EdgeNode* node() const noexcept { return node_.get(); }
    /// For STATUS=: "Sparkplug online" / "Sparkplug connecting"; empty when off.
    [[nodiscard]] std::string status() const;

private:
    void build();
    void refresh_sources();
    void retire(std::unique_ptr<sparkplug_node::EdgeNode> node);
    [[nodiscard]] sparkplug_node::NodeSnapshot snapshot();

    struct LineSample {
        std::uint64_t requests = 0;
        engine::Duration busy{};
        engine::TimePoint at{};
    };

    asio::io_context& io_;
    std::shared_ptr<spdlog::logger> logger_;
    EngineAccess engine_;
    std::string version_;
    ProbeExtras extras_;
    std::shared_ptr<const config::Config> config_;
    std::unique_ptr<sparkplug_node::EdgeNode> node_;
    DeviceSources sources_{io_, /*notices=*/false};
    std::map<std::string, LineSample, std::less<>> samples_;
    bool refresh_pending_ = false;
    std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace fieldbridge::app
