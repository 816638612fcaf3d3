#pragma once
/// @file device_sources.hpp
/// The devices a northbound consumer publishes (the JSON bridge, the Sparkplug B node):
/// one AgentSource of its own per serial device of the line engine, and the sources of
/// providers beside the engine (the R6 units of the upstream pass-through). Both
/// components rebuild them at start and after a reload that rebuilt the engine.
// Standard headers before asio's (see daemon/periodic.hpp).
#include <functional>
#include <memory>
#include <vector>

#include <asio/io_context.hpp>

#include "engine/engine.hpp"
#include "northbound/mqtt/agent_source.hpp"

namespace fieldbridge::app {

class DeviceSources {
public:
    using Source = std::shared_ptr<northbound::mqtt::DeviceSource>;
    /// More sources; asked on every rebuild(). Their owner detaches them before the
    /// objects behind them go.
    using Provider = std::function<std::vector<Source>()>;

    /// @p notices: whether the engine devices' sources pass the agents' notices on (the
    /// JSON bridge publishes them; the Sparkplug node has no place for them).
    DeviceSources(asio::io_context& io, bool notices) : io_(io), notices_(notices) {}
    ~DeviceSources() { detach(); }
    DeviceSources(const DeviceSources&) = delete;
    DeviceSources& operator=(const DeviceSources&) = delete;

    void add_provider(Provider provider) { providers_.push_back(std::move(provider)); }

    /// Detaches the sources made before, then makes one per device of @p engine (none
    /// when it is null) and appends every provider's.
    [[nodiscard]] std::vector<Source> rebuild(engine::Engine* engine);

    /// The engine devices' sources stop reaching their agents (before the engine goes).
    void detach();

private:
    asio::io_context& io_;
    bool notices_;
    std::vector<std::shared_ptr<northbound::mqtt::AgentSource>> own_;
    std::vector<Provider> providers_;
};

}  // namespace fieldbridge::app
