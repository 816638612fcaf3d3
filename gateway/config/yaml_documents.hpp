#pragma once
/// @file yaml_documents.hpp
/// The YAML stream of a configuration: its first document, and where a second one
/// starts (a configuration is one document). Replaces YAML::LoadAll, which in
/// yaml-cpp 0.7 never returns on a token that cannot start a node, such as a stray
/// ',' (jbeder/yaml-cpp #1040, found by tests/fuzz/fuzz_config_loader).

#include <yaml-cpp/yaml.h>

#include <optional>
#include <string_view>

namespace fieldbridge::config {

struct YamlDocuments {
    YAML::Node first;                 ///< null when the text holds no document
    std::optional<YAML::Mark> second;  ///< the root of a second document, if any
};

/// Reads at most three documents of @p yaml. Throws YAML::ParserException for a syntax
/// error in them, including a token the parser cannot read past (its position and
/// character in the message).
[[nodiscard]] YamlDocuments read_documents(std::string_view yaml);

}  // namespace fieldbridge::config
