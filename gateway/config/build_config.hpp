#pragma once
/// @file build_config.hpp
/// Step 3 of loading: a validated RawConfig -> the immutable Config, with the
/// defaults of config.hpp for everything the file leaves out and the derived values
/// resolved (MQTT client id and prefix, absolute file paths, the password read from
/// password_file). Internal to the config layer.

#include <filesystem>
#include <string>

#include "config/config.hpp"
#include "config/diagnostic_sink.hpp"
#include "config/raw_config.hpp"

namespace fieldbridge::config {

/// @p raw must have passed validate() without a diagnostic. Reading the password
/// file can still fail (it changed since validation): that is reported to @p sink.
[[nodiscard]] Config build_config(const RawConfig& raw, const std::filesystem::path& base_dir, std::string source_file,
                                  DiagnosticSink& sink);

}  // namespace fieldbridge::config
