// The primary host: births only while its STATE says online; offline -> NDEATH,
// disconnect, next server; malformed STATE ignored with a warning.
#include <doctest/doctest.h>

#include "session_test_support.hpp"

using namespace fieldbridge::test::sparkplug_session;
using namespace std::chrono_literals;

namespace {

constexpr const char* state_topic = "spBv1.0/STATE/scada";

ss::Session waiting_session(Clock& clock) {
    ss::Session session = make_session(settings("scada"));
    static_cast<void>(session.device_online("xeg1", xeg_metrics(), clock.now()));
    static_cast<void>(session.connecting(8));
    return session;
}

}  // namespace

TEST_CASE("with a primary host: subscribe to its STATE too, and no births before it is online "
          "(tck-id-message-flow-edge-node-birth-publish-phid-wait, tck-id-operational-behavior-edge-node-birth-sequence-wait)") {
    Clock clock;
    ss::Session session = waiting_session(clock);
    const auto actions = session.connected(clock.now());
    CHECK(topics(actions) == std::vector<std::string>{"sub spBv1.0/plant1/NCMD/gw-7", "sub spBv1.0/plant1/DCMD/gw-7/xeg1",
                                                      "sub spBv1.0/plant1/DCMD/gw-7/wtec1", "sub spBv1.0/STATE/scada"});
    CHECK(session.phase() == ss::Phase::waiting_for_host);
    CHECK(session.device_changed("xeg1", {change("position_mm", 10, 2.0)}, clock.advance(1s)).empty());
    const auto online = session.host_state(state_topic, R"({"online":true,"timestamp":100})", clock.advance(1s));
    CHECK(topics(online) == std::vector<std::string>{"pub spBv1.0/plant1/NBIRTH/gw-7",
                                                     "pub spBv1.0/plant1/DBIRTH/gw-7/xeg1",
                                                     "pub spBv1.0/plant1/DDATA/gw-7/xeg1"});
    CHECK(only<ss::Publish>(online)[2].payload.metrics[0].is_historical);
    CHECK(session.phase() == ss::Phase::online);
}

TEST_CASE("a STATE of another host is not ours (tck-id-message-flow-edge-node-birth-publish-phid-wait-id)") {
    Clock clock;
    ss::Session session = waiting_session(clock);
    static_cast<void>(session.connected(clock.now()));
    CHECK(session.host_state("spBv1.0/STATE/other", R"({"online":true,"timestamp":1})", clock.now()).empty());
    CHECK(session.phase() == ss::Phase::waiting_for_host);
}

TEST_CASE("host offline: NDEATH, disconnect and walk to the next server "
          "(tck-id-message-flow-edge-node-birth-publish-phid-offline, "
          "tck-id-operational-behavior-primary-application-state-with-multiple-servers-walk)") {
    Clock clock;
    ss::Session session = waiting_session(clock);
    static_cast<void>(session.connected(clock.now()));
    static_cast<void>(session.host_state(state_topic, R"({"online":true,"timestamp":100})", clock.now()));
    const auto actions = session.host_state(state_topic, R"({"online":false,"timestamp":100})", clock.advance(1s));
    CHECK(topics(actions) == std::vector<std::string>{"pub spBv1.0/plant1/NDEATH/gw-7", "disconnect next"});
    const auto pubs = only<ss::Publish>(actions);
    CHECK(pubs[0].payload.metrics[0].value == sp::Value{std::uint64_t{8}});
    CHECK_FALSE(pubs[0].payload.seq);
    CHECK(session.phase() == ss::Phase::disconnected);
    // Data from now on waits for the next session.
    CHECK(session.device_changed("xeg1", {change("position_mm", 10, 4.0)}, clock.advance(1s)).empty());
    CHECK(session.offline_buffer().size() == 1);
}

TEST_CASE("a retained offline STATE at connection time walks on at once") {
    Clock clock;
    ss::Session session = waiting_session(clock);
    static_cast<void>(session.connected(clock.now()));
    const auto actions = session.host_state(state_topic, R"({"online":false,"timestamp":5})", clock.now());
    CHECK(topics(actions) == std::vector<std::string>{"pub spBv1.0/plant1/NDEATH/gw-7", "disconnect next"});
}

TEST_CASE("an offline STATE older than the online one is stale and ignored "
          "(tck-id-message-flow-edge-node-birth-publish-phid-wait-timestamp)") {
    Clock clock;
    ss::Session session = waiting_session(clock);
    static_cast<void>(session.connected(clock.now()));
    static_cast<void>(session.host_state(state_topic, R"({"online":true,"timestamp":200})", clock.now()));
    CHECK(session.host_state(state_topic, R"({"online":false,"timestamp":150})", clock.now()).empty());
    CHECK(session.phase() == ss::Phase::online);
    CHECK(session.counters().stale_host_states == 1);
}

TEST_CASE("a malformed STATE is ignored with a warning whose payload text is escaped") {
    Clock clock;
    ss::Session session = waiting_session(clock);
    static_cast<void>(session.connected(clock.now()));
    const auto actions = session.host_state(state_topic, "ONLINE\n\x1b[31m", clock.now());
    const auto warnings = only<ss::Warning>(actions);
    REQUIRE(warnings.size() == 1);
    CHECK(warnings[0].text.find('\n') == std::string::npos);
    CHECK(warnings[0].text.find('\x1b') == std::string::npos);
    CHECK(warnings[0].text.find("scada") != std::string::npos);
    CHECK(only<ss::Publish>(actions).empty());
    CHECK(session.phase() == ss::Phase::waiting_for_host);
    CHECK(session.counters().malformed_host_states == 1);
    const auto legacy = only<ss::Warning>(session.host_state(state_topic, "ONLINE", clock.now()));
    REQUIRE(legacy.size() == 1);
    CHECK(legacy[0].text.find("Sparkplug 2.x") != std::string::npos);
}

TEST_CASE("a rebirth request while waiting for the host publishes nothing") {
    Clock clock;
    ss::Session session = waiting_session(clock);
    static_cast<void>(session.connected(clock.now()));
    CHECK(session.rebirth(clock.now()).empty());
}

TEST_CASE("each new connection waits for the host's STATE again") {
    Clock clock;
    ss::Session session = waiting_session(clock);
    static_cast<void>(session.connected(clock.now()));
    static_cast<void>(session.host_state(state_topic, R"({"online":true,"timestamp":100})", clock.now()));
    static_cast<void>(session.connection_lost());
    static_cast<void>(session.connecting(9));
    CHECK(only<ss::Publish>(session.connected(clock.now())).empty());
    CHECK(session.phase() == ss::Phase::waiting_for_host);
    // The other server's STATE may be older: a new session takes it as it is.
    CHECK(only<ss::Publish>(session.host_state(state_topic, R"({"online":true,"timestamp":50})", clock.now())).size() == 2);
}

TEST_CASE("stop while waiting for the host: NDEATH and disconnect") {
    Clock clock;
    ss::Session session = waiting_session(clock);
    static_cast<void>(session.connected(clock.now()));
    CHECK(topics(session.stop(clock.now())) == std::vector<std::string>{"pub spBv1.0/plant1/NDEATH/gw-7", "disconnect"});
}
