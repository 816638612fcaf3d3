#pragma once
/// @file device_definition.hpp
/// Device definition files (docs/devices.md): a device type as data, in
/// `<dir>/<name>.yaml`, found in the `definitions:` directories of the
/// configuration. The loader reads them for the devices that name them; the
/// simulator and `fieldbridge scan` read them through this header.

#include <array>
#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "config/config.hpp"
#include "config/diagnostic.hpp"
#include "core/point.hpp"
#include "core/register_def.hpp"

namespace fieldbridge::config {

/// A definition with every default applied.
struct DeviceDefinition {
    std::string name;         ///< equals the file's stem
    std::string description;  ///< for people; may be empty
    std::string file;         ///< absolute path
    WordOrder word_order = WordOrder::high_first;
    milliseconds period = seconds{1};
    core::PointModel points;  ///< points with their defaults, alarms, max_gap
    std::vector<RegisterBlock> blocks;
    std::optional<core::IdentifyRead> identify;
    /// A built-in type's hook (`behaviour:`) and its register map (`registers:`);
    /// nullopt and empty for a generic device.
    std::optional<DeviceType> behaviour;
    std::vector<core::RegisterDef> registers;
    bool operator==(const DeviceDefinition&) const = default;
};

/// Where definitions are looked for when the configuration has no `definitions:`:
/// the site's own first, then the ones shipped with the package.
inline constexpr std::array<std::string_view, 2> default_definition_dirs{"/etc/fieldbridge/devices",
                                                                         "/usr/share/fieldbridge/devices"};

/// `<dir>/<name>.yaml` of the first of @p dirs that has one.
[[nodiscard]] std::optional<std::filesystem::path> find_definition(std::string_view name,
                                                                   const std::vector<std::filesystem::path>& dirs);

/// Reads and checks one definition file; throws ConfigError with every problem
/// (file:line:col, key, what to do).
[[nodiscard]] DeviceDefinition load_definition_file(const std::filesystem::path& file);

/// Every `*.yaml` definition of @p dirs, by name (the first directory that has a
/// name wins). A file with problems is left out and its problems are added to
/// @p problems; a directory that does not exist is skipped.
[[nodiscard]] std::vector<DeviceDefinition> load_definitions(const std::vector<std::filesystem::path>& dirs,
                                                             std::vector<Diagnostic>& problems);

}  // namespace fieldbridge::config
