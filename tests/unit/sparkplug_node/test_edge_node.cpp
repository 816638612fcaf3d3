// The edge node at work (northbound/sparkplug_node/edge_node.*) over a recording MQTT
// client and fake device sources: the will per connection, births after CONNACK, DDATA
// on change, DCMDs through the command parser and runner (accepted, refused, counted),
// NCMD rebirth, DDEATH, the clean stop's NDEATH and bdSeq across node instances.
#include <doctest/doctest.h>

#include <asio/io_context.hpp>
#include <asio/post.hpp>

#include "engine/profiles/wtec_common.hpp"
#include "fake_source.hpp"
#include "northbound/sparkplug/payload_codec.hpp"
#include "northbound/sparkplug_node/edge_node.hpp"
#include "temp_dir.hpp"

namespace {

namespace fe = fieldbridge::engine;
namespace fm = fieldbridge::northbound::mqtt;
namespace fp = fieldbridge::protocol;
namespace sp = fieldbridge::northbound::sparkplug;
namespace sn = fieldbridge::northbound::sparkplug_node;

class RecordingClient final : public fm::Client {
public:
    explicit RecordingClient(asio::io_context& io) : io_(io) {}
    void set_events(fm::ClientEvents e) override { events = std::move(e); }
    void connect() override { ++connects; }
    std::uint64_t publish(const fm::Message& message) override {
        if (!online) return 0;
        if (refuse > 0) {  // the library's own queue is full for now
            --refuse;
            return 0;
        }
        published.push_back(message);
        const std::uint64_t id = ++ids;
        if (report) {
            asio::post(io_, [this, id] {
                if (events.published) events.published(id, true);
            });
        }
        return id;
    }
    void subscribe(const std::string& filter, int qos) override {
        static_cast<void>(qos);
        subscribed.push_back(filter);
    }
    void unsubscribe(const std::string& filter) override { unsubscribed.push_back(filter); }
    void set_will(const fm::Message& message) override { will = message; }
    void disconnect(std::chrono::milliseconds timeout, std::function<void()> done) override {
        static_cast<void>(timeout);
        ++disconnects;
        online = false;
        asio::post(io_, std::move(done));
    }
    bool connected() const override { return online; }
    std::size_t server_count() const override { return 2; }
    void select_server(std::size_t index) override { server = index; }

    /// The broker accepted the CONNECT.
    void accept() {
        online = true;
        events.connected();
    }

    fm::ClientEvents events;
    std::vector<fm::Message> published;
    std::vector<std::string> subscribed;
    std::vector<std::string> unsubscribed;
    fm::Message will;
    int connects = 0;
    int disconnects = 0;
    int refuse = 0;       ///< publications to refuse next
    bool report = true;   ///< report each publication as published
    std::uint64_t ids = 0;
    bool online = false;
    std::size_t server = 0;

private:
    asio::io_context& io_;
};

sp::Payload decoded(const fm::Message& message) {
    const auto result = sp::decode(message.payload);
    REQUIRE_MESSAGE(result.ok(), result.error);
    return *result.payload;
}

const sp::Metric* metric_named(const sp::Payload& payload, std::string_view name) {
    for (const auto& m : payload.metrics) {
        if (m.name && *m.name == name) return &m;
    }
    return nullptr;
}

bool has_property(const sp::Metric& metric, std::string_view key, const sp::Value& value) {
    for (const auto& p : metric.properties) {
        if (p.key == key) return p.value == value;
    }
    return false;
}

sp::CommandMetric dcmd_metric(std::string name, sp::Value value) {
    return sp::CommandMetric{sp::MetricReference{std::move(name), std::nullopt}, std::nullopt, std::move(value)};
}

std::string command_bytes(std::vector<sp::CommandMetric> metrics) {
    return sp::encode(sp::command_payload(sp::Command{std::nullopt, std::move(metrics)}));
}

struct NodeRig {
    asio::io_context io;
    fieldbridge::test::TempDir state{"fb-spb-node"};
    std::shared_ptr<fbt::FakeSource> xeg = std::make_shared<fbt::FakeSource>(io, "grip1");
    std::shared_ptr<fbt::FakeSource> wtec = std::make_shared<fbt::FakeSource>(io, "wtec1", fe::wtec_operations());
    RecordingClient* client = nullptr;
    std::unique_ptr<sn::EdgeNode> node;

    NodeRig() {
        wtec->set_fields({fe::Field{"position_pct", std::int64_t{0}, "%"}, fe::Field{"force_pct", std::int64_t{50}, "%"}});
        node = make();
    }

    std::unique_ptr<sn::EdgeNode> make() {
        sn::EdgeNodeSettings settings;
        settings.session.node = {"cell", "gw1"};
        settings.state_dir = state.path();
        auto recording = std::make_unique<RecordingClient>(io);
        client = recording.get();
        auto made = std::make_unique<sn::EdgeNode>(io, settings, std::move(recording), fe::LogSink{},
                                                   [] {
                                                       sn::NodeSnapshot s;
                                                       s.version = "9.9.9";
                                                       s.json_bridge = "off";
                                                       return s;
                                                   });
        made->set_sources({xeg, wtec});
        return made;
    }

    void run() {
        io.restart();
        io.poll();
    }

    std::vector<fm::Message> take() { return std::exchange(client->published, {}); }

    std::uint64_t alias(const sp::Payload& birth, std::string_view name) {
        const sp::Metric* m = metric_named(birth, name);
        REQUIRE(m != nullptr);
        REQUIRE(m->alias.has_value());
        return *m->alias;
    }
};

}  // namespace

TEST_CASE("the will is NDEATH with this connection's bdSeq; births come after CONNACK") {
    NodeRig rig;
    rig.node->start();
    CHECK(rig.client->connects == 1);
    CHECK(rig.client->will.topic == "spBv1.0/cell/NDEATH/gw1");
    CHECK(rig.client->will.qos == 1);
    CHECK_FALSE(rig.client->will.retained);
    const sp::Payload will = decoded(rig.client->will);
    REQUIRE(will.metrics.size() == 1);
    CHECK(will.metrics[0].name == "bdSeq");
    CHECK(will.metrics[0].value == sp::Value{std::uint64_t{0}});
    CHECK(rig.client->published.empty());

    rig.client->accept();
    CHECK(rig.client->subscribed == std::vector<std::string>{"spBv1.0/cell/NCMD/gw1", "spBv1.0/cell/DCMD/gw1/grip1",
                                                             "spBv1.0/cell/DCMD/gw1/wtec1"});
    const auto messages = rig.take();
    REQUIRE(messages.size() == 3);
    CHECK(messages[0].topic == "spBv1.0/cell/NBIRTH/gw1");
    const sp::Payload nbirth = decoded(messages[0]);
    CHECK(nbirth.seq == 0u);
    REQUIRE(metric_named(nbirth, "bdSeq") != nullptr);
    CHECK(metric_named(nbirth, "Node Control/Rebirth")->value == sp::Value{false});
    REQUIRE(metric_named(nbirth, "Properties/Software Version") != nullptr);
    CHECK(metric_named(nbirth, "Properties/Software Version")->value == sp::Value{std::string("9.9.9")});
    CHECK(metric_named(nbirth, "Properties/Commands Refused")->value == sp::Value{std::uint64_t{0}});

    CHECK(messages[1].topic == "spBv1.0/cell/DBIRTH/gw1/grip1");
    const sp::Payload xeg = decoded(messages[1]);
    CHECK(xeg.seq == 1u);
    const sp::Metric* position = metric_named(xeg, "position_mm");
    REQUIRE(position != nullptr);
    CHECK(position->value == sp::Value{10.0});
    CHECK(has_property(*position, "engUnit", std::string("mm")));
    CHECK_FALSE(has_property(*position, "writable", true));
    const sp::Metric* move = metric_named(xeg, "Commands/move");
    REQUIRE(move != nullptr);
    CHECK(move->value == sp::Value{false});
    CHECK(has_property(*move, "writable", true));
    REQUIRE(metric_named(xeg, "Commands/move/position_mm") != nullptr);
    CHECK(std::holds_alternative<std::monostate>(metric_named(xeg, "Commands/move/position_mm")->value));

    CHECK(messages[2].topic == "spBv1.0/cell/DBIRTH/gw1/wtec1");
    const sp::Payload wtec = decoded(messages[2]);
    CHECK(wtec.seq == 2u);
    CHECK(has_property(*metric_named(wtec, "force_pct"), "writable", true));
    CHECK_FALSE(has_property(*metric_named(wtec, "position_pct"), "writable", true));
}

TEST_CASE("a change is a DDATA by alias; no change, no message") {
    NodeRig rig;
    rig.node->start();
    rig.client->accept();
    const auto births = rig.take();
    const std::uint64_t position = rig.alias(decoded(births[1]), "position_mm");
    rig.xeg->set_position(20.0);
    rig.run();
    auto messages = rig.take();
    REQUIRE(messages.size() == 1);
    CHECK(messages[0].topic == "spBv1.0/cell/DDATA/gw1/grip1");
    const sp::Payload data = decoded(messages[0]);
    CHECK(data.seq == 3u);
    REQUIRE(data.metrics.size() == 1);
    CHECK(data.metrics[0].alias == position);
    CHECK_FALSE(data.metrics[0].name.has_value());
    CHECK(data.metrics[0].value == sp::Value{20.0});
    rig.xeg->set_position(20.0);
    rig.run();
    CHECK(rig.take().empty());
}

TEST_CASE("DCMDs: a writable field, an op with parameters, refusals counted and nothing written") {
    NodeRig rig;
    rig.node->start();
    rig.client->accept();
    rig.take();

    SUBCASE("force_pct by name runs the WTEC force op") {
        rig.client->events.message(fm::Message{"spBv1.0/cell/DCMD/gw1/wtec1",
                                               command_bytes({dcmd_metric("force_pct", std::uint64_t{40})}), 1, false});
        rig.run();
        REQUIRE(rig.wtec->executed.size() == 1);
        const auto* write = std::get_if<fp::WriteSingleRegisterRequest>(&rig.wtec->executed[0]);
        REQUIRE(write != nullptr);
        CHECK(write->value == 40);
        CHECK(rig.node->counters().commands_accepted == 1);
        CHECK(rig.node->counters().commands_refused == 0);
    }
    SUBCASE("Commands/move with its parameters; the parameters echoed in a DDATA") {
        rig.client->events.message(fm::Message{
            "spBv1.0/cell/DCMD/gw1/grip1",
            command_bytes({dcmd_metric("Commands/move/position_mm", 12.5), dcmd_metric("Commands/move/speed_mm_s", 20.0),
                           dcmd_metric("Commands/move", true)}),
            1, false});
        rig.run();
        CHECK_FALSE(rig.xeg->executed.empty());
        CHECK(rig.node->counters().commands_accepted == 1);
        const auto messages = rig.take();
        REQUIRE(messages.size() == 1);
        CHECK(messages[0].topic == "spBv1.0/cell/DDATA/gw1/grip1");
        CHECK(decoded(messages[0]).metrics.size() == 2);
    }
    SUBCASE("refused: unknown metric, read-only metric, undecodable bytes, out of range") {
        const std::string topic = "spBv1.0/cell/DCMD/gw1/wtec1";
        rig.client->events.message(fm::Message{topic, command_bytes({dcmd_metric("force_pct", std::uint64_t{40}),
                                                                     dcmd_metric("nope", std::uint64_t{1})}), 1, false});
        rig.client->events.message(fm::Message{topic, command_bytes({dcmd_metric("position_pct", std::uint64_t{1})}), 1, false});
        rig.client->events.message(fm::Message{topic, std::string("\xff\xff\xff", 3), 1, false});
        rig.client->events.message(fm::Message{topic, command_bytes({dcmd_metric("force_pct", std::uint64_t{1000})}), 1, false});
        rig.run();
        CHECK(rig.wtec->executed.empty());
        CHECK(rig.node->counters().commands_refused == 4);
        CHECK(rig.node->counters().commands_accepted == 0);
    }
    SUBCASE("commands off for the device") {
        rig.wtec->commands_enabled_ = false;
        rig.client->events.message(fm::Message{"spBv1.0/cell/DCMD/gw1/wtec1",
                                               command_bytes({dcmd_metric("force_pct", std::uint64_t{40})}), 1, false});
        rig.run();
        CHECK(rig.wtec->executed.empty());
        CHECK(rig.node->counters().commands_refused == 1);
    }
}

TEST_CASE("NCMD rebirth: NBIRTH and DBIRTHs again, same bdSeq, seq from 0") {
    NodeRig rig;
    rig.node->start();
    rig.client->accept();
    const auto first = rig.take();
    rig.client->events.message(
        fm::Message{"spBv1.0/cell/NCMD/gw1", command_bytes({dcmd_metric("Node Control/Rebirth", true)}), 1, false});
    rig.run();
    const auto again = rig.take();
    REQUIRE(again.size() == 3);
    CHECK(again[0].topic == "spBv1.0/cell/NBIRTH/gw1");
    CHECK(decoded(again[0]).seq == 0u);
    CHECK(metric_named(decoded(again[0]), "bdSeq")->value == metric_named(decoded(first[0]), "bdSeq")->value);
    CHECK(again[1].topic == "spBv1.0/cell/DBIRTH/gw1/grip1");
    // Anything else on NCMD is refused.
    rig.client->events.message(
        fm::Message{"spBv1.0/cell/NCMD/gw1", command_bytes({dcmd_metric("Node Control/Reboot", true)}), 1, false});
    rig.run();
    CHECK(rig.take().empty());
    CHECK(rig.node->counters().commands_refused == 1);
}

TEST_CASE("a device going offline is a DDEATH; back, a DBIRTH") {
    NodeRig rig;
    rig.node->start();
    rig.client->accept();
    rig.take();
    rig.xeg->set_online(false);
    rig.run();
    auto messages = rig.take();
    REQUIRE(messages.size() == 1);
    CHECK(messages[0].topic == "spBv1.0/cell/DDEATH/gw1/grip1");
    rig.xeg->set_online(true);
    rig.run();
    messages = rig.take();
    REQUIRE(messages.size() == 1);
    CHECK(messages[0].topic == "spBv1.0/cell/DBIRTH/gw1/grip1");
}

TEST_CASE("a clean stop publishes NDEATH then disconnects; the next node uses the next bdSeq") {
    NodeRig rig;
    rig.node->start();
    rig.client->accept();
    rig.take();
    bool done = false;
    rig.node->stop([&done] { done = true; });
    const auto messages = rig.take();
    REQUIRE(messages.size() == 1);
    CHECK(messages[0].topic == "spBv1.0/cell/NDEATH/gw1");
    CHECK(messages[0].qos == 1);
    CHECK(metric_named(decoded(messages[0]), "bdSeq")->value == sp::Value{std::uint64_t{0}});
    CHECK(rig.client->disconnects == 1);
    rig.run();
    CHECK(done);

    rig.node = rig.make();
    rig.node->start();
    CHECK(metric_named(decoded(rig.client->will), "bdSeq")->value == sp::Value{std::uint64_t{1}});
}

TEST_CASE("a lost connection walks to the next server with a new bdSeq; data waits and is replayed as history") {
    NodeRig rig;
    rig.node->start();
    rig.client->accept();
    rig.take();
    rig.client->online = false;
    rig.client->events.connection_lost("test");
    rig.xeg->set_position(30.0);
    rig.run();
    CHECK(rig.take().empty());
    CHECK(rig.node->session().offline_buffer().size() == 1);
    // The back-off (1 s) passes: the next attempt goes to the second server, bdSeq 1.
    rig.io.restart();
    rig.io.run_for(std::chrono::milliseconds(1500));
    CHECK(rig.client->connects == 2);
    CHECK(rig.client->server == 1);
    CHECK(metric_named(decoded(rig.client->will), "bdSeq")->value == sp::Value{std::uint64_t{1}});
    rig.client->accept();
    const auto messages = rig.take();
    REQUIRE(messages.size() == 4);  // NBIRTH, two DBIRTHs, the buffered DDATA
    CHECK(messages[3].topic == "spBv1.0/cell/DDATA/gw1/grip1");
    const sp::Payload replayed = decoded(messages[3]);
    REQUIRE(replayed.metrics.size() == 1);
    CHECK(replayed.metrics[0].is_historical);
    CHECK(replayed.metrics[0].value == sp::Value{30.0});
}

TEST_CASE("a device is born once with every field of its shape, not again as its first polls come in") {
    NodeRig rig;
    rig.wtec->shape_ = fe::DecodedState{{fe::Field{"position_pct", std::int64_t{1}, "%"},
                                         fe::Field{"force_pct", std::int64_t{1}, "%"},
                                         fe::Field{"speed_pct", std::int64_t{1}, "%"}}};
    rig.wtec->set_fields({fe::Field{"position_pct", std::int64_t{5}, "%"}});
    rig.node = rig.make();
    rig.node->start();
    rig.client->accept();
    const auto births = rig.take();
    REQUIRE(births.size() == 3);
    const sp::Payload wtec = decoded(births[2]);
    REQUIRE(metric_named(wtec, "speed_pct") != nullptr);
    CHECK(std::holds_alternative<std::monostate>(metric_named(wtec, "speed_pct")->value));
    CHECK(metric_named(wtec, "position_pct")->value == sp::Value{std::uint64_t{5}});
    // The next poll brings force and speed: data, no new birth.
    rig.wtec->set_fields({fe::Field{"position_pct", std::int64_t{5}, "%"}, fe::Field{"force_pct", std::int64_t{30}, "%"},
                          fe::Field{"speed_pct", std::int64_t{60}, "%"}});
    rig.run();
    const auto messages = rig.take();
    REQUIRE(messages.size() == 1);
    CHECK(messages[0].topic == "spBv1.0/cell/DDATA/gw1/wtec1");
    CHECK(decoded(messages[0]).metrics.size() == 2);
}

TEST_CASE("publications wait in order behind the window and when the client refuses them for a while") {
    NodeRig rig;
    rig.node->start();
    rig.client->refuse = 5;
    rig.client->accept();
    CHECK(rig.client->published.empty());  // NBIRTH refused: it waits, the DBIRTHs behind it
    rig.io.restart();
    rig.io.run_for(std::chrono::milliseconds(300));
    auto messages = rig.take();
    REQUIRE(messages.size() == 3);
    CHECK(messages[0].topic == "spBv1.0/cell/NBIRTH/gw1");
    CHECK(messages[1].topic == "spBv1.0/cell/DBIRTH/gw1/grip1");

    // Nothing reported published: 32 go to the client, the rest wait for reports.
    rig.client->report = false;
    for (int i = 1; i <= 40; ++i) {
        rig.xeg->set_position(10.0 + i);
        rig.run();
    }
    messages = rig.take();
    CHECK(messages.size() == 32);
    CHECK(decoded(messages.back()).metrics.at(0).value == sp::Value{42.0});
    rig.client->report = true;
    for (std::uint64_t id = 1; id <= 40; ++id) rig.client->events.published(id, true);
    rig.run();
    messages = rig.take();
    REQUIRE(messages.size() == 8);
    CHECK(decoded(messages.back()).metrics.at(0).value == sp::Value{50.0});
    CHECK(rig.node->counters().publish_dropped == 0);
}
