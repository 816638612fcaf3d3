#pragma once
/// @file builtin_map.hpp
/// The register map of a built-in device type, from its definition (docs/devices.md,
/// "Built-in types"): the rows of the definition file that replaced the compiled-in
/// one (ProfileOptions::registers), else the compiled-in definition's.

#include <memory>

#include "engine/profiles/device_profile.hpp"
#include "engine/profiles/register_map.hpp"

namespace fieldbridge::engine {

/// Throws ProfileError when @p type has no compiled-in definition and @p options
/// has no registers, or when the rows do not make a map (overlaps: the
/// configuration refuses them first).
[[nodiscard]] std::shared_ptr<const RegisterMap> builtin_register_map(DeviceType type, const ProfileOptions& options);

}  // namespace fieldbridge::engine
