#pragma once
/// @file profile_factory.hpp
/// Builds a device's profile from its type and options.

#include <memory>

#include "engine/profiles/device_profile.hpp"

namespace fieldbridge::engine {

/// Builds the profile of @p type. Throws ProfileError for options it cannot use
/// (wtec-ascii without a stroke, modbus without blocks, a block out of limits).
[[nodiscard]] std::unique_ptr<DeviceProfile> make_profile(DeviceType type, const ProfileOptions& options);

}  // namespace fieldbridge::engine
