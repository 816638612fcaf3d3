#pragma once
/// @file build_points.hpp
/// Step 3 of loading for points: validated raw points, alarms and blocks -> the
/// core::PointModel and RegisterBlocks of a device or a definition, every default
/// applied. Internal to the config layer.

#include <vector>

#include "config/config.hpp"
#include "config/device_definition.hpp"
#include "config/raw_config.hpp"

namespace fieldbridge::config {

/// The device-wide defaults of its points: the device's keys, else its definition's,
/// else the built-in ones.
struct PointDefaults {
    WordOrder word_order = WordOrder::high_first;
    milliseconds period = seconds{1};
    std::uint16_t max_gap = core::PointModel::default_max_gap;
};

[[nodiscard]] PointDefaults point_defaults(const RawDefinition* definition, const RawDevice* device);

/// The definition's points and alarms, then the device's inline ones (either may be null).
[[nodiscard]] core::PointModel build_point_model(const RawDefinition* definition, const RawDevice* device,
                                                 const PointDefaults& defaults);

[[nodiscard]] RegisterBlock build_block(const RawBlock& raw, milliseconds default_period);

/// A valid raw definition with its defaults applied.
[[nodiscard]] DeviceDefinition build_definition(const RawDefinition& raw);
/// A valid definition's `registers:` with their defaults (docs/devices.md).
[[nodiscard]] std::vector<core::RegisterDef> build_registers(const RawDefinition& raw);

}  // namespace fieldbridge::config
