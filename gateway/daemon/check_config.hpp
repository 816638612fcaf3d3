#pragma once
/// @file check_config.hpp
/// `fieldbridge --check-config FILE`.

#include <filesystem>
#include <iosfwd>

#include "daemon/config_source.hpp"

namespace fieldbridge::daemon {

/// Loads @p file with @p load. Valid: prints "FILE: configuration is valid (2 lines,
/// 4 devices, MQTT enabled)" on @p out and returns exit_ok. Invalid, missing or
/// unreadable: prints every diagnostic ("file:line:col: key: message") and a
/// closing count on @p err and returns exit_config_error.
[[nodiscard]] int check_config(const std::filesystem::path& file, const ConfigLoader& load, std::ostream& out,
                               std::ostream& err);

}  // namespace fieldbridge::daemon
