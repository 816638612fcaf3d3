// A reload re-births what changed: removed devices die, added ones are subscribed and
// born when online, redefined ones die and are born again; changed node metrics
// re-birth the whole node.
#include <doctest/doctest.h>

#include "session_test_support.hpp"

using namespace fieldbridge::test::sparkplug_session;
using namespace std::chrono_literals;

TEST_CASE("reload with the same devices and metrics publishes nothing") {
    Clock clock;
    ss::Session session = online_session(clock);
    CHECK(session.reload(node_metrics(), {{"xeg1", xeg_metrics(9)}, {"wtec1", wtec_metrics()}}, clock.now()).empty());
}

TEST_CASE("reload: a removed device gets DDEATH and its DCMD unsubscribed; an added one is subscribed") {
    Clock clock;
    ss::Session session = online_session(clock);
    const auto actions = session.reload(node_metrics(), {{"xeg1", xeg_metrics()}, {"r6a", wtec_metrics()}}, clock.now());
    CHECK(topics(actions) == std::vector<std::string>{"pub spBv1.0/plant1/DDEATH/gw-7/wtec1",
                                                      "unsub spBv1.0/plant1/DCMD/gw-7/wtec1",
                                                      "sub spBv1.0/plant1/DCMD/gw-7/r6a"});
    const auto born = session.device_online("r6a", wtec_metrics(), clock.now());
    CHECK(topics(born) == std::vector<std::string>{"pub spBv1.0/plant1/DBIRTH/gw-7/r6a"});
    CHECK(only<ss::Warning>(session.device_changed("wtec1", {change("force_pct", 20, 1)}, clock.now())).size() == 1);
}

TEST_CASE("reload: a device whose metrics changed gets DDEATH and a new DBIRTH with them") {
    Clock clock;
    ss::Session session = online_session(clock);
    auto redefined = xeg_metrics();
    redefined.push_back(metric("grip_force_n", 12, 3));
    const auto actions = session.reload(node_metrics(), {{"xeg1", redefined}, {"wtec1", wtec_metrics()}}, clock.now());
    CHECK(topics(actions) == std::vector<std::string>{"pub spBv1.0/plant1/DDEATH/gw-7/xeg1",
                                                      "pub spBv1.0/plant1/DBIRTH/gw-7/xeg1"});
    CHECK(only<ss::Publish>(actions)[1].payload.metrics.size() == 3);
}

TEST_CASE("reload: changed node metrics re-birth the whole node, same bdSeq, seq from 0") {
    Clock clock;
    ss::Session session = online_session(clock, 17);
    auto node = node_metrics();
    node.push_back(metric("Lines/bus1/State", 2, 0, sp::DataType::string));
    const auto actions = session.reload(node, {{"xeg1", xeg_metrics()}, {"wtec1", wtec_metrics()}}, clock.now());
    CHECK(topics(actions) == std::vector<std::string>{"pub spBv1.0/plant1/NBIRTH/gw-7",
                                                      "pub spBv1.0/plant1/DBIRTH/gw-7/xeg1",
                                                      "pub spBv1.0/plant1/DBIRTH/gw-7/wtec1"});
    const auto pubs = only<ss::Publish>(actions);
    CHECK(pubs[0].payload.seq == 0u);
    CHECK(find(pubs[0].payload, "bdSeq")->value == sp::Value{std::uint64_t{17}});
    CHECK(find(pubs[0].payload, "Lines/bus1/State"));
}

TEST_CASE("reload while disconnected changes the model only; the next births use it") {
    Clock clock;
    ss::Session session = make_session();
    static_cast<void>(session.device_online("xeg1", xeg_metrics(), clock.now()));
    CHECK(session.reload(node_metrics(), {{"xeg1", xeg_metrics()}}, clock.now()).empty());
    static_cast<void>(session.connecting(0));
    CHECK(topics(session.connected(clock.now())) ==
          std::vector<std::string>{"sub spBv1.0/plant1/NCMD/gw-7", "sub spBv1.0/plant1/DCMD/gw-7/xeg1",
                                   "pub spBv1.0/plant1/NBIRTH/gw-7", "pub spBv1.0/plant1/DBIRTH/gw-7/xeg1"});
}
