#pragma once
/// @file topics.hpp
/// Sparkplug B topic names (Sparkplug 3.0, "Topics and Messages"):
/// `spBv1.0/<group_id>/<message_type>/<edge_node_id>[/<device_id>]` and the primary
/// host's `spBv1.0/STATE/<host_id>`. The IDs are checked by the configuration
/// (config/sparkplug_ids.hpp); here they are only put together. Pure.
#include <string>
#include <string_view>

namespace fieldbridge::northbound::sparkplug_session {

/// tck-id-topic-structure-namespace-a: the namespace element of Sparkplug B.
inline constexpr std::string_view topic_namespace = "spBv1.0";

/// The message types an edge node publishes or receives (tck-id-topic-structure).
enum class MessageType { nbirth, ndeath, ndata, ncmd, dbirth, ddeath, ddata, dcmd };

/// "NBIRTH", "DDATA", ...
[[nodiscard]] std::string_view to_string(MessageType type) noexcept;

/// The edge node's place in the namespace: the (group, edge node) pair
/// (tck-id-topic-structure-namespace-unique-edge-node-descriptor).
struct NodeIdentity {
    std::string group_id;
    std::string edge_node_id;
    bool operator==(const NodeIdentity&) const = default;
};

/// `spBv1.0/<group>/<type>/<edge>`: NBIRTH, NDEATH, NDATA, NCMD (tck-id-topics-nbirth-topic,
/// tck-id-topics-ndata-topic, tck-id-topics-ndeath-topic, tck-id-topics-ncmd-topic).
[[nodiscard]] std::string node_topic(const NodeIdentity& node, MessageType type);

/// `spBv1.0/<group>/<type>/<edge>/<device>`: DBIRTH, DDEATH, DDATA, DCMD
/// (tck-id-topics-dbirth-topic, tck-id-topics-ddata-topic, tck-id-topics-ddeath-topic,
/// tck-id-topics-dcmd-topic; tck-id-topic-structure-namespace-device-id-associated-message-types).
[[nodiscard]] std::string device_topic(const NodeIdentity& node, MessageType type, std::string_view device);

/// `spBv1.0/STATE/<host_id>`: the primary host's state (Sparkplug 3.0).
[[nodiscard]] std::string host_state_topic(std::string_view host_id);

}  // namespace fieldbridge::northbound::sparkplug_session
