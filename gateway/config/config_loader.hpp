#pragma once
/// @file config_loader.hpp
/// Loading the configuration: YAML -> raw values with their positions
/// (raw_parse) -> validate() -> immutable Config (build_config). Every problem
/// found is reported, each with file, line, column, key path and what was expected.

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

#include "config/config.hpp"
#include "config/diagnostic.hpp"

namespace fieldbridge::config {

/// Loads, parses and validates @p path; throws ConfigError with EVERY problem found
/// (not just the first). Relative file paths in the config (TLS files, password
/// file) are resolved against the directory of @p path.
[[nodiscard]] std::shared_ptr<const Config> load_config_file(const std::filesystem::path& path);

/// The same for a YAML text; @p file_name is used in diagnostics and as
/// Config::source_file, and its directory (if any, else the current directory)
/// resolves relative file paths.
[[nodiscard]] std::shared_ptr<const Config> load_config_string(std::string_view yaml, std::string file_name);

}  // namespace fieldbridge::config
