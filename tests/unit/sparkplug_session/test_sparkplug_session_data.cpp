// DDATA: only after births, on change, by alias, under the rate rule; DDEATH / DBIRTH
// as devices go and come; the offline buffer replayed as historical.
#include <doctest/doctest.h>

#include "session_test_support.hpp"

using namespace fieldbridge::test::sparkplug_session;
using namespace std::chrono_literals;

TEST_CASE("DDATA carries the changed metrics by alias only, without datatype, QoS 0 "
          "(tck-id-topics-ddata-payload, tck-id-payloads-alias-data-cmd-requirement, tck-id-payloads-metric-datatype-not-req)") {
    Clock clock;
    ss::Session session = online_session(clock);
    const auto actions = session.device_changed("xeg1", {change("position_mm", 10, 7.0)}, clock.advance(1s));
    const auto pubs = only<ss::Publish>(actions);
    REQUIRE(pubs.size() == 1);
    CHECK(pubs[0].topic == "spBv1.0/plant1/DDATA/gw-7/xeg1");
    CHECK(pubs[0].qos == 0);
    CHECK_FALSE(pubs[0].retain);
    CHECK(pubs[0].payload.timestamp == clock.utc);
    REQUIRE(pubs[0].payload.metrics.size() == 1);
    const sp::Metric& m = pubs[0].payload.metrics[0];
    CHECK_FALSE(m.name);
    CHECK(m.alias == 10u);
    CHECK_FALSE(m.datatype);
    CHECK(m.value == sp::Value{7.0});
    CHECK(m.timestamp == clock.utc);
    CHECK_FALSE(m.is_historical);
}

TEST_CASE("no DDATA before the births (tck-id-message-flow-edge-node-birth-publish-connect)") {
    Clock clock;
    ss::Session session = make_session();
    static_cast<void>(session.device_online("xeg1", xeg_metrics(), clock.now()));
    CHECK(session.device_changed("xeg1", {change("position_mm", 10, 2.0)}, clock.now()).empty());
    static_cast<void>(session.connecting(0));
    CHECK(session.device_changed("xeg1", {change("position_mm", 10, 3.0)}, clock.now()).empty());
    CHECK(session.offline_buffer().size() == 2);
}

TEST_CASE("min_interval: a change sooner than min_interval after the previous DDATA waits for tick(), merged") {
    Clock clock;
    ss::Session session = online_session(clock);
    CHECK(only<ss::Publish>(session.device_changed("xeg1", {change("position_mm", 10, 1.0)}, clock.advance(1s))).size() == 1);
    CHECK(session.device_changed("xeg1", {change("position_mm", 10, 2.0)}, clock.advance(50ms)).empty());
    CHECK(session.device_changed("xeg1", {change("position_mm", 10, 3.0), change("speed_pct", 11, 80)},
                                 clock.advance(50ms)).empty());
    REQUIRE(session.next_deadline());
    CHECK(*session.next_deadline() == clock.mono + 100ms);
    CHECK(session.tick(clock.advance(50ms)).empty());  // 150 ms after the DDATA
    const auto pubs = only<ss::Publish>(session.tick(clock.advance(50ms)));
    REQUIRE(pubs.size() == 1);
    REQUIRE(pubs[0].payload.metrics.size() == 2);  // the latest position and the speed
    CHECK(pubs[0].payload.metrics[0].value == sp::Value{3.0});
    CHECK(pubs[0].payload.metrics[1].value == sp::Value{80.0});
    CHECK_FALSE(session.next_deadline());
}

TEST_CASE("the rate rule is per device") {
    Clock clock;
    ss::Session session = online_session(clock);
    CHECK(only<ss::Publish>(session.device_changed("xeg1", {change("position_mm", 10, 1.0)}, clock.advance(1s))).size() == 1);
    CHECK(only<ss::Publish>(session.device_changed("wtec1", {change("force_pct", 20, 1.0)}, clock.advance(10ms))).size() == 1);
}

TEST_CASE("a device going offline: its held change, then DDEATH; back online: a fresh DBIRTH "
          "(tck-id-operational-behavior-device-ddeath, tck-id-topics-ddeath-seq-num)") {
    Clock clock;
    ss::Session session = online_session(clock);
    static_cast<void>(session.device_changed("xeg1", {change("position_mm", 10, 1.0)}, clock.advance(1s)));
    static_cast<void>(session.device_changed("xeg1", {change("position_mm", 10, 2.0)}, clock.advance(10ms)));
    const auto gone = session.device_offline("xeg1", clock.advance(10ms));
    CHECK(topics(gone) == std::vector<std::string>{"pub spBv1.0/plant1/DDATA/gw-7/xeg1", "pub spBv1.0/plant1/DDEATH/gw-7/xeg1"});
    CHECK(seqs(gone) == std::vector<std::uint64_t>{4, 5});
    CHECK(session.device_changed("xeg1", {change("position_mm", 10, 5.0)}, clock.advance(1s)).empty());
    const auto back = session.device_online("xeg1", xeg_metrics(6.0), clock.advance(1s));
    CHECK(topics(back) == std::vector<std::string>{"pub spBv1.0/plant1/DBIRTH/gw-7/xeg1"});
    const auto pubs = only<ss::Publish>(back);
    CHECK(find(pubs[0].payload, "position_mm")->value == sp::Value{6.0});
    CHECK(pubs[0].payload.seq == 6u);
}

TEST_CASE("an event for a device that is not configured is a warning, counted, and publishes nothing") {
    Clock clock;
    ss::Session session = online_session(clock);
    const auto actions = session.device_changed("ghost\n1", {change("x", 1, 1)}, clock.now());
    const auto warnings = only<ss::Warning>(actions);
    REQUIRE(warnings.size() == 1);
    CHECK(warnings[0].text.find("\"ghost\\n1\"") != std::string::npos);  // escaped
    CHECK(only<ss::Publish>(actions).empty());
    CHECK(session.counters().unknown_devices == 1);
}

TEST_CASE("node metrics: NDATA on change (tck-id-operational-behavior-data-publish-nbirth-change)") {
    Clock clock;
    ss::Session session = online_session(clock);
    const auto pubs = only<ss::Publish>(session.node_changed({change("Properties/Software Version", 1, 2)}, clock.advance(1s)));
    REQUIRE(pubs.size() == 1);
    CHECK(pubs[0].topic == "spBv1.0/plant1/NDATA/gw-7");
    CHECK(pubs[0].payload.seq == 3u);
}

TEST_CASE("broker away: DDATA waits in the offline buffer and follows the births as historical, oldest first") {
    Clock clock;
    ss::Session session = online_session(clock, 1);
    static_cast<void>(session.connection_lost());
    const std::uint64_t first = clock.advance(1s).utc_ms;
    CHECK(session.device_changed("xeg1", {change("position_mm", 10, 1.0)}, clock.now()).empty());
    CHECK(session.device_changed("xeg1", {change("position_mm", 10, 2.0)}, clock.advance(1s)).empty());
    CHECK(session.node_changed({change("Properties/Software Version", 1, 3)}, clock.advance(1s)).empty());
    CHECK(session.offline_buffer().size() == 3);
    static_cast<void>(session.connecting(2));
    const auto actions = session.connected(clock.advance(1s));
    CHECK(topics(actions) == std::vector<std::string>{
                                 "sub spBv1.0/plant1/NCMD/gw-7", "sub spBv1.0/plant1/DCMD/gw-7/xeg1",
                                 "sub spBv1.0/plant1/DCMD/gw-7/wtec1", "pub spBv1.0/plant1/NBIRTH/gw-7",
                                 "pub spBv1.0/plant1/DBIRTH/gw-7/xeg1", "pub spBv1.0/plant1/DBIRTH/gw-7/wtec1",
                                 "pub spBv1.0/plant1/DDATA/gw-7/xeg1", "pub spBv1.0/plant1/DDATA/gw-7/xeg1",
                                 "pub spBv1.0/plant1/NDATA/gw-7"});
    CHECK(seqs(actions) == std::vector<std::uint64_t>{0, 1, 2, 3, 4, 5});
    const auto pubs = only<ss::Publish>(actions);
    CHECK(find(pubs[1].payload, "position_mm")->value == sp::Value{2.0});  // DBIRTH: the current value
    const sp::Metric& oldest = pubs[3].payload.metrics[0];
    CHECK(oldest.is_historical);
    CHECK(oldest.value == sp::Value{1.0});
    CHECK(oldest.timestamp == first);  // when it was produced
    CHECK(pubs[4].payload.metrics[0].is_historical);
    CHECK(pubs[5].payload.metrics[0].is_historical);
    CHECK(session.offline_buffer().size() == 0);
}

TEST_CASE("a buffered DDATA whose device is offline at replay time is dropped and counted") {
    Clock clock;
    ss::Session session = online_session(clock);
    static_cast<void>(session.connection_lost());
    static_cast<void>(session.device_changed("xeg1", {change("position_mm", 10, 1.0)}, clock.advance(1s)));
    static_cast<void>(session.device_offline("xeg1", clock.advance(1s)));
    static_cast<void>(session.connecting(4));
    const auto actions = session.connected(clock.advance(1s));
    CHECK(topics(actions).back() == "pub spBv1.0/plant1/DBIRTH/gw-7/wtec1");
    CHECK(session.offline_buffer().dropped() == 1);
}

TEST_CASE("changes held back by the rate rule when the connection drops go to the buffer") {
    Clock clock;
    ss::Session session = online_session(clock);
    static_cast<void>(session.device_changed("xeg1", {change("position_mm", 10, 1.0)}, clock.advance(1s)));
    static_cast<void>(session.device_changed("xeg1", {change("position_mm", 10, 2.0)}, clock.advance(10ms)));
    static_cast<void>(session.connection_lost());
    CHECK(session.offline_buffer().size() == 1);
    CHECK_FALSE(session.next_deadline());
}

TEST_CASE("the offline buffer's bounds apply to the session (settings)") {
    Clock clock;
    ss::SessionSettings s = settings();
    s.offline_max_messages = 2;
    ss::Session session = make_session(s);
    static_cast<void>(session.device_online("xeg1", xeg_metrics(), clock.now()));
    for (int i = 0; i < 5; ++i) {
        static_cast<void>(session.device_changed("xeg1", {change("position_mm", 10, i)}, clock.advance(1s)));
    }
    CHECK(session.offline_buffer().size() == 2);
    CHECK(session.offline_buffer().dropped() == 3);
}
