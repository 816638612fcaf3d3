#pragma once
/// @file device_probe.hpp
/// What the line scan asks a bus address and what it concludes from the answers.
/// Pure: requests out, replies in, no port and no clock (the LineScanner drives it
/// through the line master).
///
/// Modbus-RTU, per address (ModbusProbe):
///  1. presence: FC03, the first holding register. Any valid reply, an exception
///     included, means a device listens at that address; no reply ends the probe.
///  2. HIWIN XEG: FC03 of the model register (engine::xeg_identification()) reads one
///     of the model codes the XEG profile knows (engine::xeg_model_limits()).
///  3. WTEC-485 in RTU mode: FC03 of the device ID register
///     (engine::wtec_rtu_identification()) reads the address the device answered from.
///  4. EXCD203MB: FC03 of `ver` (engine::excd_identification(), a 32-bit query
///     register) is answered with two registers.
///  5. device definitions (docs/devices.md): each definition's `identify:` read
///     (DefinitionIdentify, FC03 / FC04), in the order given; the first whose reply
///     holds exactly its `expect` values (or, without `expect`, that is answered at
///     all) names the device.
///  6. anything else is a generic Modbus device.
/// The registers are the profiles' (docs/architecture.md, "Device knowledge"); the
/// probe holds none.
/// Every request is a read: nothing a scan sends can move or reconfigure a device.
///
/// WTEC-485 ASCII: `$` (read all stations, seed 003 command 2) goes to address 00
/// and every ASCII device answers from its own address; parse_stations() reads the
/// replies, and each station is confirmed with `A` (read the firmware version).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/point.hpp"
#include "engine/profiles/device_profile.hpp"
#include "protocol/bytes.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::scan {

/// The identify read of one device definition.
struct DefinitionIdentify {
    std::string name;  ///< the definition's name: the device's `type:`
    core::IdentifyRead read;
};

/// A device the scan found.
struct FoundDevice {
    std::uint8_t address = 0;
    engine::DeviceType type = engine::DeviceType::modbus;
    /// What identified it, for the snippet's comment: "XEG-32 (model <model code>)".
    std::string detail;
    /// modbus only: the first holding register answered with a value (so a block
    /// there is known to be readable).
    bool holding_zero_readable = false;
    /// modbus only: the device definition whose identify read matched ("" when none).
    std::string definition;
    bool operator==(const FoundDevice&) const = default;
};

/// The identification sequence of one Modbus-RTU address.
class ModbusProbe {
public:
    /// @p definitions are tried in order once the built-in types are ruled out.
    explicit ModbusProbe(std::uint8_t address, std::vector<DefinitionIdentify> definitions = {});

    /// The read to send next; nullopt when the probe is finished.
    [[nodiscard]] std::optional<protocol::Request> next() const;
    /// The reply to the request next() gave; nullopt when none came in time.
    /// Precondition: next() has a value (throws std::logic_error otherwise).
    void on_reply(const std::optional<protocol::Response>& reply);

    [[nodiscard]] bool finished() const noexcept { return step_ == Step::finished; }
    /// After finished(): the device, or nullopt when nothing answered.
    [[nodiscard]] const std::optional<FoundDevice>& result() const noexcept { return found_; }

private:
    enum class Step : std::uint8_t { presence, xeg_model, wtec_id, excd_version, definitions, finished };

    void identified(engine::DeviceType type, std::string detail);
    /// No built-in type: the definitions' identify reads, then a generic device.
    void try_definitions(std::size_t from);

    std::uint8_t address_;
    std::vector<DefinitionIdentify> definitions_;
    std::size_t definition_ = 0;  ///< Step::definitions: the one being tried
    Step step_ = Step::presence;
    bool holding_zero_readable_ = false;
    std::optional<FoundDevice> found_;
};

/// The stations named by every valid `$` reply in @p rx (bytes that arrived after the
/// query, several frames possible, noise skipped), ascending and without duplicates.
[[nodiscard]] std::vector<std::uint8_t> parse_stations(protocol::ByteView rx);

}  // namespace fieldbridge::scan
