#pragma once
/// @file device_source.hpp
/// What the MQTT bridge needs of one device, whatever drives it: a serial device's
/// DeviceAgent (agent_source.hpp) or an upstream R6 unit. The bridge never reaches
/// into the engine; it reads snapshots, hears about changes and sends commands
/// through this interface. Loop thread only.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/point.hpp"
#include "engine/device_agent.hpp"
#include "engine/profiles/device_profile.hpp"
#include "engine/register_image.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::northbound::mqtt {

/// One register value the source holds (SourceState::raw).
using RawRegister = engine::RegisterValue;

/// One look at a device.
struct SourceState {
    bool online = false;
    /// offline while the device is offline; else the worst quality of the known
    /// registers (stale before good); unknown when nothing was read yet.
    engine::Quality quality = engine::Quality::unknown;
    /// When the newest register value arrived; nullopt when none has.
    std::optional<engine::TimePoint> updated;
    engine::DecodedState decoded;
    std::vector<RawRegister> raw;  ///< by table, then address
};

/// What a source reports to the bridge (both on the loop thread).
struct SourceListener {
    std::function<void()> changed;                           ///< state or alarms may differ
    std::function<void(const engine::DeviceNotice&)> notice;  ///< e.g. XEG FC07 exception status
};

class DeviceSource {
public:
    DeviceSource() = default;
    virtual ~DeviceSource() = default;
    DeviceSource(const DeviceSource&) = delete;
    DeviceSource& operator=(const DeviceSource&) = delete;

    /// The configured device name: a topic level.
    [[nodiscard]] virtual const std::string& name() const = 0;
    /// The configured type ("hiwin-xeg", ..., "r6").
    [[nodiscard]] virtual std::string_view type() const = 0;
    /// The MQTT operations of its type (its profile's; none but the raw register ops
    /// for a generic Modbus device): docs/mqtt.md, "Commands".
    [[nodiscard]] virtual engine::OperationSet operations() const = 0;
    /// The device's named points (generic Modbus devices with points or a definition
    /// file); nullptr when it has none. They add the ops `write` and `read`.
    [[nodiscard]] virtual const core::PointModel* points() const { return nullptr; }
    /// False: `mqtt_commands: false` in the device's config; every command is refused.
    [[nodiscard]] virtual bool commands_enabled() const = 0;

    [[nodiscard]] virtual SourceState state() const = 0;
    /// Every field its state can have, with placeholder values (what the device's
    /// metrics are before its registers are read: the Sparkplug node births it once,
    /// not once per register block that comes in). Default: the current state's.
    [[nodiscard]] virtual engine::DecodedState shape() const { return state().decoded; }
    [[nodiscard]] virtual std::vector<engine::Alarm> alarms() const = 0;

    /// Replaces the listener; an empty one stops the reports.
    virtual void set_listener(SourceListener listener) = 0;

    /// The local exception the request would get without touching the device
    /// (spec §4: 0x01 / 0x02 / 0x03); nullopt when it may be sent.
    [[nodiscard]] virtual std::optional<protocol::ExceptionCode> validate(const protocol::Request& request) const = 0;
    /// Sends @p request through the device's command lane (priority, deadline);
    /// @p done is called exactly once, on the loop thread, never inside execute().
    virtual void execute(const protocol::Request& request, engine::ResponseHandler done) = 0;
};

}  // namespace fieldbridge::northbound::mqtt
