// Northbound sections: gateway id, Modbus TCP listeners / allow-list / rules,
// upstreams, MQTT (URI, credentials, TLS files, topics, timing), metrics_http.

#include <doctest/doctest.h>

#include <chrono>
#include <filesystem>
#include <fstream>

#include "config_test_support.hpp"

using namespace fieldbridge::config;
using namespace fieldbridge::config::test;

TEST_CASE("gateway id") {
    CHECK_REPORTS("gateway: {id: \"\"}\n", "gateway.id", 1, 15, "not a valid id");
    CHECK_REPORTS("gateway: {id: cell/7}\n", "gateway.id", 1, 15, "'cell/7' is not a valid id", "MQTT topics");
    CHECK_REPORTS("gateway: {id: " + std::string(65, 'a') + "}\n", "gateway.id", 1, 15, "1..64 characters");
    CHECK(diagnostics_of("gateway: {id: " + std::string(64, 'a') + "}\n").empty());
    CHECK_REPORTS("gateway: {id: t, log_level: verbose}\n", "gateway.log_level", 1, 29,
                  "expected one of: trace, debug, info, warning, error");
}

TEST_CASE("modbus_tcp: listen addresses, limits, allow-list and rules") {
    const char* yaml = R"(
gateway: {id: t}
modbus_tcp:
  listen: ["localhost:502", "0.0.0.0:502", "0.0.0.0:502", "[::1]:99999"]
  max_connections: 2000
  idle_timeout: 1441min
  allow: [10.0.0.0/8, "10.1.2.3/8", 300.0.0.0/8]
  rules:
    - {clients: [10.0.0.0/33], functions: [0, 128], units: [300], action: deny}
    - {units: [9], registers: {from: 0x20, to: 0x10}, action: allow}
    - {registers: {from: 0x10}, action: deny}
)";
    CHECK_REPORTS(yaml, "modbus_tcp.listen[0]", 3, 12, "'localhost' is not an IPv4 address", "[::1]:1502");
    CHECK_REPORTS(yaml, "modbus_tcp.listen[2]", 3, 44, "0.0.0.0:502 is listed twice");
    CHECK_REPORTS(yaml, "modbus_tcp.listen[3]", 3, 59, "'99999' is not a port");
    CHECK_REPORTS(yaml, "modbus_tcp.max_connections", 4, 20, "expected 1..1024");
    CHECK_REPORTS(yaml, "modbus_tcp.idle_timeout", 5, 17, "expected 0ms..1440min");
    CHECK_REPORTS(yaml, "modbus_tcp.allow[1]", 6, 23, "host bits set", "did you mean 10.0.0.0/8?");
    CHECK_REPORTS(yaml, "modbus_tcp.allow[2]", 6, 37, "'300.0.0.0' is not an IP address");
    CHECK_REPORTS(yaml, "modbus_tcp.rules[0].clients[0]", 8, 18, "invalid prefix length", "/0../32");
    CHECK_REPORTS(yaml, "modbus_tcp.rules[0].functions[0]", 8, 44, "0 is out of range; expected 1..127");
    CHECK_REPORTS(yaml, "modbus_tcp.rules[0].functions[1]", 8, 47, "128 is out of range");
    CHECK_REPORTS(yaml, "modbus_tcp.rules[0].units[0]", 8, 61, "300 is out of range; expected 0..255");
    CHECK_REPORTS(yaml, "modbus_tcp.rules[1].units[0]", 9, 16, "unit 9 is not configured");
    CHECK_REPORTS(yaml, "modbus_tcp.rules[1].registers.to", 9, 48, "0x0010 is below from (0x0020)");
    CHECK_REPORTS(yaml, "modbus_tcp.rules[2].registers.to", 10, 19, "required key is missing");
    CHECK(diagnostics_of(yaml).size() == 14);

    CHECK_REPORTS("gateway: {id: t}\nmodbus_tcp: {listen: []}\n", "modbus_tcp.listen", 2, 22, "is empty");
    CHECK_REPORTS("gateway: {id: t}\nmodbus_tcp: {listen: [\"::1:502\"]}\n", "modbus_tcp.listen[0]", 2, 23,
                  "needs brackets");
}

TEST_CASE("modbus_tcp: frame deadline and per-client connection cap") {
    const char* yaml = R"(
gateway: {id: t}
modbus_tcp:
  frame_timeout: 5ms
  max_connections_per_client: 0
)";
    CHECK_REPORTS(yaml, "modbus_tcp.frame_timeout", 3, 18, "expected 10ms..1min");
    CHECK_REPORTS(yaml, "modbus_tcp.max_connections_per_client", 4, 31, "expected 1..1024");
    CHECK(diagnostics_of(yaml).size() == 2);
    CHECK_REPORTS("gateway: {id: t}\nmodbus_tcp: {frame_timeout: 2min}\n", "modbus_tcp.frame_timeout", 2, 29,
                  "expected 10ms..1min");
    CHECK(diagnostics_of("gateway: {id: t}\nmodbus_tcp: {frame_timeout: 60s, max_connections_per_client: 1024}\n")
              .empty());
}

TEST_CASE("mqtt command bounds, outbox bytes and the upstream sequence hold are range-checked") {
    const char* yaml = R"(
gateway: {id: t}
upstreams:
  - {name: r6, host: 127.0.0.1, sequence_max_hold: 5ms, units: [{unit_id: 50, name: r6}]}
mqtt:
  max_command_bytes: 100
  max_command_id_length: 5000
  max_queued_commands: 0
  max_queued_command_bytes: 10
  outbox_max_bytes: 1024
  outbox_max_messages: 15
)";
    CHECK_REPORTS(yaml, "upstreams[0].sequence_max_hold", 3, 52, "expected 10ms..10s");
    CHECK_REPORTS(yaml, "mqtt.max_command_bytes", 5, 22, "expected 256..1048576");
    CHECK_REPORTS(yaml, "mqtt.max_command_id_length", 6, 26, "expected 8..4096");
    CHECK_REPORTS(yaml, "mqtt.max_queued_commands", 7, 24, "expected 1..4096");
    CHECK_REPORTS(yaml, "mqtt.max_queued_command_bytes", 8, 29, "expected 1024..67108864");
    CHECK_REPORTS(yaml, "mqtt.outbox_max_bytes", 9, 21, "expected 65536..268435456");
    CHECK_REPORTS(yaml, "mqtt.outbox_max_messages", 10, 24, "expected 16..1000000");
    CHECK(diagnostics_of(yaml).size() == 7);
}

TEST_CASE("upstreams") {
    const char* yaml = R"(
gateway: {id: t}
upstreams:
  - name: r6
    host: "r6:502"
    port: 0
    connect_timeout: 5ms
    response_timeout: 2s
    command_ttl: 1s
    queue_limit: 0
    poll_period: 5ms
    reconnect_backoff: {initial: 0ms}
    units:
      - {unit_id: 0, upstream_unit: 256, name: robot arm}
  - name: r7
    host: 10.0.0.7
  - name: r8
    host: 10.0.0.8
    units: []
)";
    CHECK_REPORTS(yaml, "upstreams[0].host", 4, 11, "'r6:502' is not a host name or IP address", "use port");
    CHECK_REPORTS(yaml, "upstreams[0].port", 5, 11, "expected 1..65535");
    CHECK_REPORTS(yaml, "upstreams[0].connect_timeout", 6, 22, "expected 10ms..1min");
    CHECK_REPORTS(yaml, "upstreams[0].command_ttl", 8, 18, "1s is shorter than response_timeout (2s)",
                  "expected at least 2s");
    CHECK_REPORTS(yaml, "upstreams[0].queue_limit", 9, 18, "expected 1..1024");
    CHECK_REPORTS(yaml, "upstreams[0].poll_period", 10, 18, "expected 10ms..60min");
    CHECK_REPORTS(yaml, "upstreams[0].reconnect_backoff.initial", 11, 34, "expected 10ms..60min");
    CHECK_REPORTS(yaml, "upstreams[0].units[0].unit_id", 13, 19, "0 is out of range; expected 1..247");
    CHECK_REPORTS(yaml, "upstreams[0].units[0].upstream_unit", 13, 37, "expected 0..255");
    CHECK_REPORTS(yaml, "upstreams[0].units[0].name", 13, 48, "'robot arm' is not a valid name");
    CHECK_REPORTS(yaml, "upstreams[1].units", 14, 5, "required key is missing", "unit_id: 50");
    CHECK_REPORTS(yaml, "upstreams[2].units", 18, 12, "is empty");
    CHECK(diagnostics_of(yaml).size() == 12);
}

TEST_CASE("mqtt values") {
    const char* yaml = R"(
gateway: {id: t}
mqtt:
  uri: mqtt://broker
  client_id: "my client"
  password: secret
  qos: 3
  keep_alive: 1500ms
  prefix: "plant/#"
  heartbeat: 1s
  min_interval: 2s
  deadband: {position_mm: -1, 2bad: 1}
  diag_period: 500ms
  reconnect_backoff: {initial: 2min, max: 1min}
)";
    CHECK_REPORTS(yaml, "mqtt.uri", 3, 8, "unsupported scheme 'mqtt'", "tcp://host:1883");
    CHECK_REPORTS(yaml, "mqtt.client_id", 4, 14, "not a usable client id", "without spaces");
    CHECK_REPORTS(yaml, "mqtt.password", 5, 13, "a password needs a username in MQTT 3.1.1");
    CHECK_REPORTS(yaml, "mqtt.qos", 6, 8, "expected 0..2");
    CHECK_REPORTS(yaml, "mqtt.keep_alive", 7, 15, "not whole seconds");
    CHECK_REPORTS(yaml, "mqtt.prefix", 8, 11, "contains a wildcard");
    CHECK_REPORTS(yaml, "mqtt.heartbeat", 9, 14, "heartbeat (1s) is shorter than min_interval (2s)");
    CHECK_REPORTS(yaml, "mqtt.deadband.position_mm", 11, 27, "is negative");
    CHECK_REPORTS(yaml, "mqtt.deadband.2bad", 11, 31, "not a state field name");
    CHECK_REPORTS(yaml, "mqtt.diag_period", 12, 16, "expected 1s..60min");
    CHECK_REPORTS(yaml, "mqtt.reconnect_backoff.max", 13, 43, "max (1min) is shorter than initial (2min)");
    CHECK(diagnostics_of(yaml).size() == 11);

    for (const auto* prefix : {"/plant", "plant/", "a//b", "$SYS/x", "a+b"}) {
        INFO(prefix);
        CHECK_REPORTS("gateway: {id: t}\nmqtt: {prefix: \"" + std::string(prefix) + "\"}\n", "mqtt.prefix", 2, 16,
                      "expected topic levels");
    }
    CHECK(diagnostics_of("gateway: {id: t}\nmqtt: {prefix: plant/cell-7, version: \"5\", password: x}\n").empty());
    CHECK(diagnostics_of("gateway: {id: t}\nmqtt: {username: u, password: x, keep_alive: 0s}\n").empty());
}

TEST_CASE("mqtt TLS and credential files") {
    const auto dir = std::filesystem::temp_directory_path() /
                     ("fb-config-tls-" + std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "key.pem") << "key";
    const std::string file = (dir / "fb.yaml").string();

    const char* yaml = R"(
gateway: {id: t}
mqtt:
  uri: tcp://broker:1883
  username: u
  password: p
  password_file: missing-secret
  tls:
    ca_file: no-ca.pem
    key_file: key.pem
)";
    const auto diagnostics = diagnostics_of(yaml, file);
    const auto none_verified = diagnostics_of("gateway: {id: t}\nmqtt: {tls: {verify: false}}\n", file);
    const auto ssl_missing = diagnostics_of("gateway: {id: t}\nmqtt: {uri: \"ssl://b\", tls: {cert_file: /no/cert.pem}}\n", file);
    std::filesystem::remove_all(dir);

    INFO(dump(diagnostics));
    REQUIRE(diagnostics.size() == 5);
    const auto at = [&](std::size_t i, std::string_view key, int line, int column, std::string_view fragment) {
        CHECK(diagnostics[i].key == key);
        CHECK(diagnostics[i].line == line);
        CHECK(diagnostics[i].column == column);
        CHECK_MESSAGE(diagnostics[i].message.find(fragment) != std::string::npos, diagnostics[i].message);
    };
    at(0, "mqtt.password_file", 6, 18, "password and password_file are both set");
    at(1, "mqtt.password_file", 6, 18, "file not found: " + (dir / "missing-secret").string());
    at(2, "mqtt.tls", 8, 5, "TLS settings need an ssl:// or wss:// uri");
    at(3, "mqtt.tls.ca_file", 8, 14, "file not found: " + (dir / "no-ca.pem").string());
    at(4, "mqtt.tls.key_file", 9, 15, "key_file is set without cert_file");

    INFO(dump(none_verified));
    REQUIRE(none_verified.size() == 1);
    CHECK(none_verified[0].key == "mqtt.tls");
    INFO(dump(ssl_missing));
    REQUIRE(ssl_missing.size() == 1);
    CHECK(ssl_missing[0].key == "mqtt.tls.cert_file");
    CHECK(ssl_missing[0].message.find("file not found: /no/cert.pem") != std::string::npos);
}

TEST_CASE("metrics_http") {
    CHECK_REPORTS("gateway: {id: t}\nmodbus_tcp: {listen: [\"127.0.0.1:9102\"]}\nmetrics_http: {listen: \"0.0.0.0:9102\"}\n",
                  "metrics_http.listen", 3, 24, "collides with the Modbus TCP listener 127.0.0.1:9102");
    CHECK_REPORTS("gateway: {id: t}\nmetrics_http: {listen: \"127.0.0.1:502\"}\n", "metrics_http.listen", 2, 24,
                  "collides with the Modbus TCP listener 0.0.0.0:502");
    CHECK_REPORTS("gateway: {id: t}\nmetrics_http: {listen: nope}\n", "metrics_http.listen", 2, 24, "has no port");
    CHECK(diagnostics_of("gateway: {id: t}\nmetrics_http: {listen: \"127.0.0.1:9103\"}\n").empty());
}

TEST_CASE("mqtt.uri may be a list of brokers, tried in order; all with TLS or none") {
    const auto config = load_ok("gateway: {id: t}\nmqtt:\n  uri: [tcp://a:1883, tcp://b:1884]\n");
    CHECK(config->mqtt.uris == std::vector<std::string>{"tcp://a:1883", "tcp://b:1884"});
    CHECK_FALSE(config->mqtt.uses_tls());
    CHECK(load_ok("gateway: {id: t}\nmqtt:\n  uri: [ssl://a:8883, wss://b/mqtt]\n")->mqtt.uses_tls());
    const std::string mixed = "gateway: {id: t}\nmqtt:\n  uri: [tcp://a:1883, ssl://b:8883]\n";
    CHECK_REPORTS(mixed, "mqtt.uri[1]", 3, 23, "uses TLS and the first URI does not");
    const std::string empty = "gateway: {id: t}\nmqtt:\n  uri: []\n";
    CHECK_REPORTS(empty, "mqtt.uri", 3, 8, "the list is empty");
    const std::string bad = "gateway: {id: t}\nmqtt:\n  uri: [tcp://a:1883, \"mqtt://b\"]\n";
    CHECK_REPORTS(bad, "mqtt.uri[1]", 3, 23, "unsupported scheme 'mqtt'");
}
