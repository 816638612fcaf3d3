// Session establishment: the will, the subscriptions, NBIRTH then DBIRTHs, seq, rebirth, stop.
#include <doctest/doctest.h>

#include "session_test_support.hpp"

using namespace fieldbridge::test::sparkplug_session;
using namespace std::chrono_literals;

TEST_CASE("the will is NDEATH with only bdSeq (Int64), QoS 1, not retained, no seq "
          "(tck-id-message-flow-edge-node-birth-publish-will-message-qos, -will-retained, tck-id-topics-ndeath-seq)") {
    ss::Session session = make_session();
    const auto actions = session.connecting(42);
    REQUIRE(actions.size() == 1);
    const auto* will = std::get_if<ss::SetWill>(&actions[0]);
    REQUIRE(will);
    CHECK(will->topic == "spBv1.0/plant1/NDEATH/gw-7");
    CHECK(will->qos == 1);
    CHECK_FALSE(will->retain);
    CHECK_FALSE(will->payload.seq);
    REQUIRE(will->payload.metrics.size() == 1);  // tck-id-topics-ndeath-payload
    const sp::Metric& bd = will->payload.metrics[0];
    CHECK(bd.name == "bdSeq");
    CHECK(bd.datatype == sp::DataType::int64);
    CHECK(bd.value == sp::Value{std::uint64_t{42}});
    CHECK_FALSE(bd.alias);
    CHECK(session.phase() == ss::Phase::connecting);
}

TEST_CASE("on CONNACK: NCMD and DCMD subscriptions at QoS 1 before the NBIRTH, then one DBIRTH per online device "
          "(tck-id-message-flow-edge-node-ncmd-subscribe, tck-id-message-flow-device-birth-publish-nbirth-wait)") {
    Clock clock;
    ss::Session session = make_session();
    static_cast<void>(session.device_online("xeg1", xeg_metrics(), clock.now()));  // wtec1 stays offline
    static_cast<void>(session.connecting(7));
    const auto actions = session.connected(clock.now());
    CHECK(topics(actions) == std::vector<std::string>{
                                 "sub spBv1.0/plant1/NCMD/gw-7", "sub spBv1.0/plant1/DCMD/gw-7/xeg1",
                                 "sub spBv1.0/plant1/DCMD/gw-7/wtec1", "pub spBv1.0/plant1/NBIRTH/gw-7",
                                 "pub spBv1.0/plant1/DBIRTH/gw-7/xeg1"});
    for (const auto& sub : only<ss::Subscribe>(actions)) CHECK(sub.qos == 1);
    CHECK(session.phase() == ss::Phase::online);
}

TEST_CASE("NBIRTH: seq 0, QoS 0, not retained, timestamp, bdSeq of the will, Node Control/Rebirth false never aliased, "
          "every node metric (tck-id-topics-nbirth-seq-num, tck-id-topics-nbirth-mqtt, tck-id-topics-nbirth-bdseq-matching, "
          "tck-id-topics-nbirth-rebirth-metric, tck-id-topics-nbirth-metric-reqs)") {
    Clock clock;
    ss::Session session = make_session();
    static_cast<void>(session.connecting(9));
    const auto pubs = only<ss::Publish>(session.connected(clock.now()));
    REQUIRE(!pubs.empty());
    const ss::Publish& nbirth = pubs[0];
    CHECK(nbirth.qos == 0);
    CHECK_FALSE(nbirth.retain);
    CHECK(nbirth.payload.seq == 0u);
    CHECK(nbirth.payload.timestamp == clock.utc);
    REQUIRE(nbirth.payload.metrics.size() == 3);
    const sp::Metric* bd = find(nbirth.payload, "bdSeq");
    REQUIRE(bd);
    CHECK(bd->value == sp::Value{std::uint64_t{9}});
    CHECK(bd->datatype == sp::DataType::int64);
    const sp::Metric* rebirth = find(nbirth.payload, "Node Control/Rebirth");
    REQUIRE(rebirth);
    CHECK(rebirth->datatype == sp::DataType::boolean);
    CHECK(rebirth->value == sp::Value{false});
    CHECK_FALSE(rebirth->alias);
    const sp::Metric* version = find(nbirth.payload, "Properties/Software Version");
    REQUIRE(version);
    CHECK(version->alias == 1u);
    for (const sp::Metric& m : nbirth.payload.metrics) CHECK(m.timestamp);  // Ignition needs them
}

TEST_CASE("DBIRTH: every metric with name, alias, datatype and current value; seq +1 "
          "(tck-id-topics-dbirth-metric-reqs, tck-id-topics-dbirth-seq, tck-id-topics-dbirth-mqtt)") {
    Clock clock;
    ss::Session session = make_session();
    static_cast<void>(session.device_online("xeg1", xeg_metrics(4.25), clock.now()));
    static_cast<void>(session.device_online("wtec1", wtec_metrics(), clock.now()));
    static_cast<void>(session.connecting(0));
    const auto actions = session.connected(clock.now());
    CHECK(seqs(actions) == std::vector<std::uint64_t>{0, 1, 2});
    const auto pubs = only<ss::Publish>(actions);
    const ss::Publish& dbirth = pubs[1];
    CHECK(dbirth.topic == "spBv1.0/plant1/DBIRTH/gw-7/xeg1");
    CHECK(dbirth.qos == 0);
    CHECK_FALSE(dbirth.retain);
    REQUIRE(dbirth.payload.metrics.size() == 2);
    const sp::Metric& position = dbirth.payload.metrics[0];
    CHECK(position.name == "position_mm");
    CHECK(position.alias == 10u);
    CHECK(position.datatype == sp::DataType::float64);
    CHECK(position.value == sp::Value{4.25});
    CHECK(position.timestamp);
}

TEST_CASE("with aliases off, births and DDATA carry names only") {
    Clock clock;
    ss::SessionSettings s = settings();
    s.aliases = false;
    ss::Session session = make_session(s);
    static_cast<void>(session.device_online("xeg1", xeg_metrics(), clock.now()));
    static_cast<void>(session.connecting(0));
    for (const auto& pub : only<ss::Publish>(session.connected(clock.now()))) {
        for (const sp::Metric& m : pub.payload.metrics) CHECK_FALSE(m.alias);
    }
    const auto pubs = only<ss::Publish>(session.device_changed("xeg1", {change("position_mm", 10, 7.0)}, clock.advance(1s)));
    REQUIRE(pubs.size() == 1);
    CHECK(pubs[0].payload.metrics[0].name == "position_mm");
    CHECK_FALSE(pubs[0].payload.metrics[0].alias);
}

TEST_CASE("seq goes +1 on every message but NDEATH and wraps 255 -> 0 (tck-id-payloads-sequence-num-incrementing)") {
    Clock clock;
    ss::Session session = online_session(clock);  // NBIRTH 0, DBIRTH 1, DBIRTH 2
    std::vector<std::uint64_t> seen;
    for (int i = 0; i < 300; ++i) {
        const auto actions = session.device_changed("wtec1", {change("force_pct", 20, i)}, clock.advance(1s));
        for (const auto s : seqs(actions)) seen.push_back(s);
    }
    REQUIRE(seen.size() == 300);
    CHECK(seen[0] == 3);
    CHECK(seen[252] == 255);
    CHECK(seen[253] == 0);
    CHECK(seen[299] == 46);
    const auto stop = session.stop(clock.now());
    const auto pubs = only<ss::Publish>(stop);
    REQUIRE(pubs.size() == 1);
    CHECK_FALSE(pubs[0].payload.seq);
}

TEST_CASE("NCMD rebirth: NBIRTH and every DBIRTH again, same bdSeq, seq from 0 "
          "(tck-id-operational-behavior-data-commands-rebirth-action-2, -action-3)") {
    Clock clock;
    ss::Session session = online_session(clock, 200);
    static_cast<void>(session.device_changed("xeg1", {change("position_mm", 10, 9.5)}, clock.advance(1s)));
    const auto actions = session.rebirth(clock.advance(1s));
    CHECK(topics(actions) == std::vector<std::string>{"pub spBv1.0/plant1/NBIRTH/gw-7",
                                                      "pub spBv1.0/plant1/DBIRTH/gw-7/xeg1",
                                                      "pub spBv1.0/plant1/DBIRTH/gw-7/wtec1"});
    CHECK(seqs(actions) == std::vector<std::uint64_t>{0, 1, 2});
    const auto pubs = only<ss::Publish>(actions);
    CHECK(find(pubs[0].payload, "bdSeq")->value == sp::Value{std::uint64_t{200}});
    CHECK(find(pubs[1].payload, "position_mm")->value == sp::Value{9.5});  // the current value
    CHECK(session.bd_seq() == 200);
    CHECK(session.counters().rebirths == 1);
}

TEST_CASE("a new connection takes the new bdSeq into its will and NBIRTH (tck-id-topics-nbirth-bdseq-matching)") {
    Clock clock;
    ss::Session session = online_session(clock, 5);
    static_cast<void>(session.connection_lost());
    CHECK(session.phase() == ss::Phase::disconnected);
    const auto will = only<ss::SetWill>(session.connecting(6));
    REQUIRE(will.size() == 1);
    CHECK(will[0].payload.metrics[0].value == sp::Value{std::uint64_t{6}});
    const auto pubs = only<ss::Publish>(session.connected(clock.now()));
    CHECK(find(pubs[0].payload, "bdSeq")->value == sp::Value{std::uint64_t{6}});
    CHECK(pubs[0].payload.seq == 0u);
}

TEST_CASE("clean stop: the node publishes NDEATH (bdSeq, QoS 1) and then disconnects "
          "(tck-id-operational-behavior-edge-node-intentional-disconnect-ndeath, -packet)") {
    Clock clock;
    ss::Session session = online_session(clock, 11);
    const auto actions = session.stop(clock.now());
    CHECK(topics(actions) == std::vector<std::string>{"pub spBv1.0/plant1/NDEATH/gw-7", "disconnect"});
    const auto pubs = only<ss::Publish>(actions);
    CHECK(pubs[0].qos == 1);
    REQUIRE(pubs[0].payload.metrics.size() == 1);
    CHECK(pubs[0].payload.metrics[0].value == sp::Value{std::uint64_t{11}});
    CHECK(session.phase() == ss::Phase::stopped);
    CHECK(session.connecting(12).empty());  // stopped stays stopped
}

TEST_CASE("stop without a connection publishes nothing") {
    ss::Session session = make_session();
    CHECK(session.stop(Clock{}.now()).empty());
}
