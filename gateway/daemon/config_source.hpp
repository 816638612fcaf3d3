#pragma once
/// @file config_source.hpp
/// How the daemon obtains a configuration: main() passes
/// config::load_config_file; tests pass a function returning prepared configs or
/// throwing config::ConfigError.

#include <filesystem>
#include <functional>
#include <memory>

#include "config/config.hpp"

namespace fieldbridge::daemon {

/// Loads and validates the file; throws config::ConfigError listing every problem.
using ConfigLoader = std::function<std::shared_ptr<const config::Config>(const std::filesystem::path&)>;

}  // namespace fieldbridge::daemon
