#pragma once
/// @file device_factory.hpp
/// Builds a simulated bus device from its type name, as used by the simulator
/// configuration and command line ("hiwin-xeg", "excd203mb", "wtec-rtu", "wtec-ascii",
/// "modbus", or the name of a device definition given in the options).

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "models/bus_device.hpp"
#include "models/definition_model.hpp"

namespace fieldbridge::sim {

/// Per-device options; each model reads only the fields that concern it.
struct DeviceOptions {
    /// WTEC-485 full stroke in encoder counts (position 0..stroke).
    std::uint32_t wtec_stroke = 20000;
    /// Gripper connected to the XEG-C2 controller, as its model code in holding register
    /// 0x0600 (seed 001 section 3.3): 0x0A10 XEG-16, 0x0A20 XEG-32, 0x0A21 XEG-32-PR,
    /// 0x0A30 XEG-48, 0x0A40 XEG-64.
    std::uint16_t xeg_model = 0x0A20;
    /// EXCD203MB 32-bit register word order: "high_first" (default, as the CRC-verified
    /// solm+ example of manual 002 shows) or "low_first".
    std::string excd_word_order = "high_first";
    /// Set when the device's type names a device definition (--definitions,
    /// --definition): make_device() then builds a DefinitionModel of it.
    std::shared_ptr<const DefinitionSpec> definition;
};

/// The type names make_device() accepts.
[[nodiscard]] std::vector<std::string_view> device_types();

/// Creates a device of @p type at bus @p address. Throws std::invalid_argument with an
/// operator-readable message for an unknown type, an invalid address or invalid options.
[[nodiscard]] std::unique_ptr<BusDevice> make_device(std::string_view type, std::uint8_t address,
                                                     const DeviceOptions& options);

}  // namespace fieldbridge::sim
