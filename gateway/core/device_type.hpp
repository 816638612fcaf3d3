#pragma once
/// @file device_type.hpp
/// The device types of the gateway (spec §5), used by the configuration, the engine's
/// profiles, scan and MQTT alike.

#include <cstdint>
#include <optional>
#include <string_view>

#include "core/names.hpp"

namespace fieldbridge::core {

enum class DeviceType : std::uint8_t { hiwin_xeg, excd203mb, wtec_rtu, wtec_ascii, modbus };

/// The spelling of the config file and of MQTT state.
inline constexpr NameTable<DeviceType, 5> device_type_names{{
    {"hiwin-xeg", DeviceType::hiwin_xeg},
    {"excd203mb", DeviceType::excd203mb},
    {"wtec-rtu", DeviceType::wtec_rtu},
    {"wtec-ascii", DeviceType::wtec_ascii},
    {"modbus", DeviceType::modbus},
}};
template <>
struct Names<DeviceType> {
    static constexpr const auto& table = device_type_names;
};

/// The behaviour hooks a device definition may name (`behaviour:`, docs/devices.md,
/// "Built-in types"): the built-in types, whose C++ (engine/profiles/profile_factory.cpp)
/// holds what is not data. `modbus` is no hook: a definition without one is generic.
inline constexpr NameTable<DeviceType, 4> behaviour_names{{
    {"hiwin-xeg", DeviceType::hiwin_xeg},
    {"excd203mb", DeviceType::excd203mb},
    {"wtec-rtu", DeviceType::wtec_rtu},
    {"wtec-ascii", DeviceType::wtec_ascii},
}};

}  // namespace fieldbridge::core
