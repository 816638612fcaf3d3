#pragma once
/// @file sparkplug_ids.hpp
/// The Sparkplug B rules for the IDs that become topic levels: group_id,
/// edge_node_id and device_id (Sparkplug 3.0, "Topics and Messages":
/// tck-id-topic-structure-namespace-valid-group-id, -valid-edge-node-id,
/// -valid-device-id): non-empty valid UTF-8 without `+`, `/` and `#`. MQTT itself
/// forbids U+0000 in a topic (MQTT 3.1.1 section 1.5.3), so that is refused too.
#include <optional>
#include <string>
#include <string_view>

namespace fieldbridge::config {

/// What is wrong with @p id as a Sparkplug ID, for the operator; nullopt when it is valid.
[[nodiscard]] std::optional<std::string> sparkplug_id_problem(std::string_view id);

}  // namespace fieldbridge::config
