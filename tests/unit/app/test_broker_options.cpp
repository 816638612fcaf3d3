// The Paho options of the two northbounds' broker connections (the JSON bridge's
// mqtt::paho_options, the edge node's sparkplug_paho_options): what they share comes
// from their sections alike (mqtt::connection_options), the rest is each one's own.
#include <doctest/doctest.h>

#include <chrono>
#include <string>
#include <vector>

#include "app/sparkplug_component.hpp"
#include "northbound/mqtt/paho_client.hpp"
#include "northbound/sparkplug/command_decoder.hpp"

namespace fc = fieldbridge::config;
namespace fm = fieldbridge::northbound::mqtt;

namespace {

/// Sets the fields both sections have to the same values, servers aside.
template <typename Section>
void shared_fields(Section& section) {
    section.client_id = "box-7";
    section.username = "edge";
    section.password = "s3cret";
    section.tls.ca_file = "/etc/fieldbridge/ca.pem";
    section.tls.verify = false;
    section.keep_alive = std::chrono::milliseconds{45000};
}

void check_shared_fields(const fm::PahoOptions& o, const std::vector<std::string>& servers) {
    CHECK(o.uri == servers.front());
    CHECK(o.servers == servers);
    CHECK(o.client_id == "box-7");
    CHECK(o.username == "edge");
    CHECK(o.password == "s3cret");
    CHECK(o.tls);
    CHECK(o.tls_files.ca_file == "/etc/fieldbridge/ca.pem");
    CHECK_FALSE(o.tls_files.verify);
    CHECK(o.keep_alive == std::chrono::seconds{45});
}

}  // namespace

TEST_CASE("the JSON bridge's connection: its section's brokers, identity and session, its retained will") {
    fc::MqttConfig config;
    shared_fields(config);
    config.uris = {"ssl://a.example:8883", "ssl://b.example:8883"};
    config.version = fc::MqttVersion::v5;
    config.clean_session = false;
    config.qos = 2;
    config.max_command_bytes = 4096;
    config.max_queued_commands = 10;
    config.max_queued_command_bytes = 2048;

    const fm::PahoOptions o = fm::paho_options(config, "fieldbridge/box-7/status");
    check_shared_fields(o, config.uris);
    CHECK(o.version == fc::MqttVersion::v5);
    CHECK_FALSE(o.clean_session);
    CHECK(o.will.topic == "fieldbridge/box-7/status");
    CHECK(o.will.payload == "offline");
    CHECK(o.will.qos == 2);
    CHECK(o.will.retained);
    CHECK(o.max_payload_bytes == 4096);
    CHECK(o.max_inbound_messages == 10);
    CHECK(o.max_inbound_bytes == 2048);
    // MQTT 5 bounds the packets the broker may send: the largest command and headroom.
    CHECK(o.max_packet_bytes == 4096 + fm::packet_headroom_bytes);

    config.version = fc::MqttVersion::v3_1_1;
    CHECK(fm::paho_options(config, "t").max_packet_bytes == 0);  // 3.1.1 has no such property
}

TEST_CASE("the edge node's connection: its section's brokers and identity, Sparkplug's session rules") {
    fc::SparkplugConfig config;
    shared_fields(config);
    config.servers = {"tcp://a.example:1883", "ssl://b.example:8883"};  // TLS when any server is ssl://

    const fm::PahoOptions o = fieldbridge::app::sparkplug_paho_options(config);
    check_shared_fields(o, config.servers);
    // Sparkplug 3.0: MQTT 3.1.1, clean session; the will (NDEATH) is set per connection.
    CHECK(o.version == fc::MqttVersion::v3_1_1);
    CHECK(o.clean_session);
    CHECK(o.will.topic.empty());
    CHECK(o.max_payload_bytes == fieldbridge::northbound::sparkplug::CommandLimits{}.max_bytes);
}
