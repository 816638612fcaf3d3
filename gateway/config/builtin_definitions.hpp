#pragma once
/// @file builtin_definitions.hpp
/// The built-in device types as definitions (docs/devices.md, "Built-in types"):
/// `config/devices/<type>.yaml`, installed under /usr/share/fieldbridge/devices and
/// compiled into the binary from the same files. A file of the type's name in the
/// configuration's `definitions:` directories wins; without one, the compiled-in copy
/// is used, so a box whose file went missing keeps its devices.

#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "config/device_definition.hpp"

namespace fieldbridge::config {

/// One compiled-in definition: the type's name and the file's text.
struct BuiltinText {
    std::string_view name;
    std::string_view text;
};

/// Every compiled-in definition (generated from config/devices/ at build time).
[[nodiscard]] std::span<const BuiltinText> builtin_definition_texts() noexcept;

/// Where diagnostics of a compiled-in definition point: "(built in)/<type>.yaml".
[[nodiscard]] std::string builtin_definition_path(std::string_view name);

/// The compiled-in definition of @p type, read once; nullptr for a type without
/// one (`modbus`). Throws ConfigError if it has problems (the build's tests load
/// every one, so a shipped binary has none).
[[nodiscard]] const DeviceDefinition* builtin_definition(DeviceType type);

}  // namespace fieldbridge::config
