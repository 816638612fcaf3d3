#pragma once
/// @file agent_source.hpp
/// A serial device (its DeviceAgent) as a DeviceSource of the MQTT bridge: state and
/// alarms from the agent's profile over its register image, change notifications
/// from the image's subscription and the agent's notices, commands through
/// DeviceAgent::request (the same validation, command lane and deadline as Modbus
/// TCP writes).
///
/// The engine owns the agent and may be rebuilt (reload): detach() before that
/// forgets the agent without touching it; a detached source reports the device
/// offline and answers commands 0x0A. Loop thread only.
#include <memory>
#include <string>

#include "engine/device_agent.hpp"
#include "northbound/mqtt/device_source.hpp"

namespace fieldbridge::northbound::mqtt {

class AgentSource final : public DeviceSource {
public:
    /// @p notices: take the agent's notice callback (one taker per agent: the JSON
    /// bridge's source; the Sparkplug node's sources do without notices).
    AgentSource(asio::io_context& io, engine::DeviceAgent& agent, bool commands_enabled, bool notices = true);
    ~AgentSource() override;

    [[nodiscard]] const std::string& name() const override { return name_; }
    [[nodiscard]] std::string_view type() const override;
    /// The profile's, kept: valid after detach() (operations.hpp: static storage).
    [[nodiscard]] engine::OperationSet operations() const override { return operations_; }
    [[nodiscard]] const core::PointModel* points() const override {
        return points_.points.empty() ? nullptr : &points_;
    }
    [[nodiscard]] bool commands_enabled() const override { return commands_enabled_; }
    [[nodiscard]] SourceState state() const override;
    /// The profile's decoding of an image with every register of the device's address
    /// range known (varying values, so that no field is left out for a zero).
    [[nodiscard]] engine::DecodedState shape() const override;
    [[nodiscard]] std::vector<engine::Alarm> alarms() const override;
    void set_listener(SourceListener listener) override;
    [[nodiscard]] std::optional<protocol::ExceptionCode> validate(const protocol::Request& request) const override;
    void execute(const protocol::Request& request, engine::ResponseHandler done) override;

    /// The agent is about to be destroyed (or already is): never touch it again.
    void detach() noexcept;

private:
    asio::io_context& io_;
    engine::DeviceAgent* agent_;
    std::string name_;
    std::string type_;
    engine::OperationSet operations_;
    core::PointModel points_;  ///< kept: valid after detach()
    bool commands_enabled_;
    bool notices_;
    engine::RegisterImage::SubscriptionId subscription_ = 0;
    // Shared with the image's listener and the notice callback, which the engine
    // may call after this source is gone (it holds them, not the other way round).
    std::shared_ptr<SourceListener> listener_;
};

/// The state of any image, as the bridge sees it (also for tests).
[[nodiscard]] SourceState image_state(const engine::DeviceProfile& profile, const engine::RegisterImage& image,
                                      bool online);

}  // namespace fieldbridge::northbound::mqtt
