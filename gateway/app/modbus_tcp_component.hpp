#pragma once
/// @file modbus_tcp_component.hpp
/// The Modbus TCP side as a daemon component: the server, the upstream (R6)
/// pass-through targets, and the routing table from unit IDs to targets (serial
/// devices of the engine, lines' broadcast units, upstream units). Routes follow the
/// engine: they are dropped before it is rebuilt and set again from the new one.
#include <asio/io_context.hpp>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <spdlog/logger.h>
#include <string>
#include <vector>

#include "app/engine_component.hpp"
#include "core/modbus_ids.hpp"
#include "daemon/component.hpp"
#include "northbound/modbus_tcp/server.hpp"
#include "northbound/targets/line_broadcast_target.hpp"
#include "northbound/targets/serial_device_target.hpp"
#include "northbound/upstream/upstream_target.hpp"

namespace fieldbridge::app {

class ModbusTcpComponent final : public daemon::Component {
public:
    /// @p engine must be registered before this component (it starts first).
    /// @p inherited: sockets passed by systemd for modbus_tcp.listen entries
    /// (match_passed_sockets()); owned from here on, the server takes them at start().
    ModbusTcpComponent(asio::io_context& io, std::shared_ptr<spdlog::logger> logger, EngineComponent& engine,
                       std::vector<northbound::modbus_tcp::InheritedListener> inherited = {});
    ~ModbusTcpComponent() override;

    [[nodiscard]] std::string name() const override { return "Modbus TCP server"; }
    void start(daemon::StartContext& context) override;
    void stop(daemon::StopContext& context) override;
    /// Binds new listen addresses (a reload that cannot is rejected as a whole).
    void prepare(const config::Config& next) override;
    void abandon() noexcept override;
    void apply(std::shared_ptr<const config::Config> config) override;

    /// The upstream targets, one per configured upstream (for the MQTT R6 sources).
    [[nodiscard]] const std::vector<std::unique_ptr<northbound::upstream::UpstreamTarget>>& upstreams() const noexcept {
        return upstreams_;
    }
    /// Nullptr before start() and after stop().
    [[nodiscard]] const northbound::modbus_tcp::ModbusTcpServer* server() const noexcept { return server_.get(); }
    /// For STATUS=.
    [[nodiscard]] std::string status() const;
    /// Called just before the upstream targets are destroyed (stop, or a reload that
    /// changes the upstreams): whoever holds them (MQTT R6 sources) lets go.
    void on_upstreams_closing(std::function<void()> listener) { upstreams_closing_.push_back(std::move(listener)); }

private:
    void build_upstreams();
    void stop_upstreams();
    /// Serial and broadcast targets from @p engine (nullptr: none), then every route.
    void rebuild_routes(engine::Engine* engine);

    asio::io_context& io_;
    std::shared_ptr<spdlog::logger> logger_;
    EngineComponent& engine_;
    std::shared_ptr<const config::Config> config_;
    std::unique_ptr<northbound::modbus_tcp::ModbusTcpServer> server_;
    std::vector<std::unique_ptr<northbound::upstream::UpstreamTarget>> upstreams_;
    /// The targets of one line (its devices, then its broadcast unit) and the unit of
    /// each, with the line's worker and revision they were built for.
    struct LineTargets {
        const engine::LineWorker* worker = nullptr;
        std::uint64_t revision = 0;
        std::vector<std::unique_ptr<northbound::UnitTarget>> targets;
        std::vector<core::UnitId> units;
    };
    std::map<std::string, LineTargets, std::less<>> line_targets_;  ///< by line name
    std::vector<std::function<void()>> upstreams_closing_;
    std::vector<northbound::modbus_tcp::InheritedListener> inherited_;  ///< until start() hands them over
};

}  // namespace fieldbridge::app
