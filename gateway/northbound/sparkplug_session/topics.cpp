#include "northbound/sparkplug_session/topics.hpp"

namespace fieldbridge::northbound::sparkplug_session {

std::string_view to_string(MessageType type) noexcept {
    switch (type) {
    case MessageType::nbirth: return "NBIRTH";
    case MessageType::ndeath: return "NDEATH";
    case MessageType::ndata: return "NDATA";
    case MessageType::ncmd: return "NCMD";
    case MessageType::dbirth: return "DBIRTH";
    case MessageType::ddeath: return "DDEATH";
    case MessageType::ddata: return "DDATA";
    case MessageType::dcmd: return "DCMD";
    }
    return "UNKNOWN";
}

std::string node_topic(const NodeIdentity& node, MessageType type) {
    std::string topic{topic_namespace};
    topic += '/';
    topic += node.group_id;
    topic += '/';
    topic += to_string(type);
    topic += '/';
    topic += node.edge_node_id;
    return topic;
}

std::string device_topic(const NodeIdentity& node, MessageType type, std::string_view device) {
    std::string topic = node_topic(node, type);
    topic += '/';
    topic += device;
    return topic;
}

std::string host_state_topic(std::string_view host_id) {
    std::string topic{topic_namespace};
    topic += "/STATE/";
    topic += host_id;
    return topic;
}

}  // namespace fieldbridge::northbound::sparkplug_session
