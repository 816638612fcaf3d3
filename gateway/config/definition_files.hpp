#pragma once
/// @file definition_files.hpp
/// Reading device definition files for the loader: the raw definition of a file
/// with its own problems, and the lookup of every device's `type:` that is not a
/// built-in type. Internal to the config layer.

#include <filesystem>
#include <memory>
#include <vector>

#include "config/diagnostic_sink.hpp"
#include "config/raw_config.hpp"

namespace fieldbridge::config {

/// Reads, parses and checks @p file (an absolute path). Its problems are added to
/// @p problems, in its file; returns null when there is one.
[[nodiscard]] std::shared_ptr<const RawDefinition> read_definition(const std::filesystem::path& file,
                                                                   std::vector<Diagnostic>& problems);

/// Parses and checks the definition @p text, reported as in @p file (whose name
/// without `.yaml` is @p stem). Its problems are added to @p problems; returns null
/// when there is one.
[[nodiscard]] std::shared_ptr<const RawDefinition> parse_definition_text(std::string_view text,
                                                                         const std::string& file,
                                                                         std::string_view stem,
                                                                         std::vector<Diagnostic>& problems);

/// For every device whose `type:` is not a built-in type: finds the definition in
/// the configuration's `definitions:` directories (relative to @p base_dir; the
/// defaults when absent), reads it once per name, and sets the device's `definition`
/// and `type` (modbus). A name not found, or a definition with problems, is reported
/// (the device's `type` is then marked invalid, so nothing else reports it again).
/// A definition with `behaviour:` makes the device of that built-in type. A built-in
/// type's own name takes `<type>.yaml` from the directories when one is there (it
/// must name the same behaviour), else nothing: the compiled-in definition.
void resolve_definitions(RawConfig& raw, const std::filesystem::path& base_dir, DiagnosticSink& sink);

/// The directories `definitions:` names, resolved against @p base_dir, or the defaults.
[[nodiscard]] std::vector<std::filesystem::path> definition_dirs(const RawConfig& raw,
                                                                 const std::filesystem::path& base_dir);

}  // namespace fieldbridge::config
