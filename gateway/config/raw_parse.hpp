#pragma once
/// @file raw_parse.hpp
/// Step 1 of loading: the YAML tree -> RawConfig. Reports the kind of every node,
/// unknown and duplicate keys, and values that do not convert to their type
/// (integers, durations, booleans, enumerations, addresses). Limits, required keys
/// and relations between values are validate()'s job. Internal to the config layer.

#include <yaml-cpp/yaml.h>

#include "config/diagnostic_sink.hpp"
#include "config/raw_config.hpp"
#include "config/yaml_reader.hpp"

namespace fieldbridge::config {

/// @p root is the document's root node.
[[nodiscard]] RawConfig parse_raw(const YAML::Node& root, DiagnosticSink& sink);

/// The `lines` section (raw_parse_lines.cpp).
[[nodiscard]] RawSeq<RawLine> parse_lines(const MapReader& root);

/// One `blocks:` entry (raw_parse_lines.cpp).
[[nodiscard]] RawBlock parse_block(const NodeRef& ref, DiagnosticSink& sink);

/// `points:` and `alarms:` lists of a device or a definition (raw_parse_points.cpp).
[[nodiscard]] RawSeq<RawPoint> parse_points(const MapReader& map, std::string_view key);
[[nodiscard]] RawSeq<RawAlarm> parse_alarms(const MapReader& map, std::string_view key);

/// A device definition file's root node; @p sink reports in that file.
[[nodiscard]] RawDefinition parse_definition(const YAML::Node& root, std::string file, DiagnosticSink& sink);

/// A `{initial, max}` back-off map.
[[nodiscard]] RawBackoff parse_backoff(const NodeRef& ref, DiagnosticSink& sink);

}  // namespace fieldbridge::config
