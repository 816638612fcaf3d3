#pragma once
/// @file builtin_map.hpp
/// The register map and the state points of a built-in device type, from its
/// definition (docs/devices.md, "Built-in types"): the definition file's that replaced
/// the compiled-in one (ProfileOptions::registers, ::builtin_state), else the
/// compiled-in definition's.

#include <memory>

#include "engine/profiles/device_profile.hpp"
#include "engine/profiles/register_map.hpp"

namespace fieldbridge::engine {

/// Throws ProfileError when @p type has no compiled-in definition and @p options
/// has no registers, or when the rows do not make a map (overlaps: the
/// configuration refuses them first).
[[nodiscard]] std::shared_ptr<const RegisterMap> builtin_register_map(DeviceType type, const ProfileOptions& options);

/// The points and alarms that decode the state of @p type (empty for a type whose
/// hook still decodes its state in C++). Throws ProfileError as builtin_register_map().
[[nodiscard]] core::PointModel builtin_state_points(DeviceType type, const ProfileOptions& options);

}  // namespace fieldbridge::engine
