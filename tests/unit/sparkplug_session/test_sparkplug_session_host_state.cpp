// The primary host's STATE payload and the ordering rules an edge node applies to it.
#include <doctest/doctest.h>

#include <string>

#include "northbound/sparkplug_session/host_state.hpp"

namespace {

namespace ss = fieldbridge::northbound::sparkplug_session;

}  // namespace

TEST_CASE("a 3.0 STATE payload is read (tck-id-host-topic-phid-birth-payload)") {
    const auto online = ss::parse_host_state(R"({"online":true,"timestamp":1668114759262})");
    REQUIRE(online.state);
    CHECK(*online.state == ss::HostState{true, 1668114759262u});
    CHECK(online.problem.empty());
    const auto offline = ss::parse_host_state(R"({"timestamp":5,"online":false,"extra":[1,2]})");
    REQUIRE(offline.state);
    CHECK(*offline.state == ss::HostState{false, 5});
}

TEST_CASE("a malformed STATE payload is a problem, never a state") {
    for (const char* bad : {"", "{", "[]", "42", R"({"online":"true","timestamp":1})", R"({"online":true})",
                            R"({"timestamp":1})", R"({"online":true,"timestamp":-1})",
                            R"({"online":true,"timestamp":1.5})", R"({"online":1,"timestamp":1})",
                            "{\"online\":true,\"timestamp\":1}\xff"}) {
        CAPTURE(bad);
        const auto parsed = ss::parse_host_state(bad);
        CHECK_FALSE(parsed.state);
        CHECK_FALSE(parsed.problem.empty());
    }
}

TEST_CASE("the legacy 2.x ONLINE / OFFLINE payloads are refused with a message that says why") {
    for (const char* legacy : {"ONLINE", "OFFLINE"}) {
        const auto parsed = ss::parse_host_state(legacy);
        CHECK_FALSE(parsed.state);
        CHECK(parsed.problem.find("Sparkplug 2.x") != std::string::npos);
    }
}

TEST_CASE("a STATE payload beyond the bound is refused unread") {
    std::string big = R"({"online":true,"timestamp":1,"pad":")";
    big += std::string(ss::max_host_state_bytes, 'x');
    big += "\"}";
    const auto parsed = ss::parse_host_state(big);
    CHECK_FALSE(parsed.state);
    CHECK(parsed.problem.find("more than") != std::string::npos);
}

TEST_CASE("the tracker: first STATE taken as it is, older ones ignored (tck-id-message-flow-edge-node-birth-publish-phid-wait-timestamp)") {
    ss::HostTracker tracker;
    CHECK_FALSE(tracker.online());
    CHECK(tracker.observe({true, 100}) == ss::HostVerdict::online);
    CHECK(tracker.online());
    CHECK(tracker.observe({true, 100}) == ss::HostVerdict::unchanged);
    CHECK(tracker.observe({false, 99}) == ss::HostVerdict::stale);  // an old death after a new birth
    CHECK(tracker.online());
    CHECK(tracker.observe({false, 100}) == ss::HostVerdict::offline);  // same timestamp: the matching death
    CHECK_FALSE(tracker.online());
    CHECK(tracker.observe({true, 200}) == ss::HostVerdict::online);
    tracker.reset();
    CHECK_FALSE(tracker.online());
    CHECK(tracker.observe({true, 1}) == ss::HostVerdict::online);  // a new session starts over
}

TEST_CASE("the tracker: a first STATE that says offline is an offline verdict") {
    ss::HostTracker tracker;
    CHECK(tracker.observe({false, 7}) == ss::HostVerdict::offline);
}
