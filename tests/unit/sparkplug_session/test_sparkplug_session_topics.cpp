// Sparkplug topic names (tck-id-topic-structure and the per-message topic statements).
#include <doctest/doctest.h>

#include "northbound/sparkplug_session/topics.hpp"

namespace {

namespace ss = fieldbridge::northbound::sparkplug_session;

const ss::NodeIdentity node{"plant1", "gw-7"};

}  // namespace

TEST_CASE("node topics: spBv1.0/<group>/<type>/<edge> (tck-id-topics-nbirth-topic, tck-id-topics-ndeath-topic)") {
    CHECK(ss::node_topic(node, ss::MessageType::nbirth) == "spBv1.0/plant1/NBIRTH/gw-7");
    CHECK(ss::node_topic(node, ss::MessageType::ndeath) == "spBv1.0/plant1/NDEATH/gw-7");
    CHECK(ss::node_topic(node, ss::MessageType::ndata) == "spBv1.0/plant1/NDATA/gw-7");
    CHECK(ss::node_topic(node, ss::MessageType::ncmd) == "spBv1.0/plant1/NCMD/gw-7");
}

TEST_CASE("device topics add the device ID (tck-id-topic-structure-namespace-device-id-associated-message-types)") {
    CHECK(ss::device_topic(node, ss::MessageType::dbirth, "xeg1") == "spBv1.0/plant1/DBIRTH/gw-7/xeg1");
    CHECK(ss::device_topic(node, ss::MessageType::ddata, "xeg1") == "spBv1.0/plant1/DDATA/gw-7/xeg1");
    CHECK(ss::device_topic(node, ss::MessageType::ddeath, "xeg1") == "spBv1.0/plant1/DDEATH/gw-7/xeg1");
    CHECK(ss::device_topic(node, ss::MessageType::dcmd, "xeg1") == "spBv1.0/plant1/DCMD/gw-7/xeg1");
}

TEST_CASE("the primary host's STATE topic is spBv1.0/STATE/<host_id>") {
    CHECK(ss::host_state_topic("scada-a") == "spBv1.0/STATE/scada-a");
}
