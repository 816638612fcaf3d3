// Structural errors: YAML syntax, unknown keys at every level, duplicate keys,
// wrong kinds and types, missing required keys, several errors at once.

#include <doctest/doctest.h>

#include <algorithm>

#include "config_test_support.hpp"

using namespace fieldbridge::config;
using namespace fieldbridge::config::test;

TEST_CASE("a YAML syntax error is a diagnostic with its position") {
    const auto diagnostics = diagnostics_of(R"(
gateway:
  id: t
 log_level: info
)");
    INFO(dump(diagnostics));
    REQUIRE(diagnostics.size() == 1);
    CHECK(diagnostics[0].key.empty());
    CHECK(diagnostics[0].line == 3);
    CHECK(diagnostics[0].message.find("YAML syntax error") != std::string::npos);

    const auto unclosed = diagnostics_of("gateway: {id: t}\nlines: [1, 2\n");
    INFO(dump(unclosed));
    REQUIRE(unclosed.size() == 1);
    CHECK(unclosed[0].line >= 2);
    CHECK(unclosed[0].message.find("YAML syntax error") != std::string::npos);
}

// Found by fuzz_config_loader: yaml-cpp 0.7's LoadAll never returns on a stray ','
// (jbeder/yaml-cpp #1040): it appends empty documents without reading on, until the
// memory runs out. The loader must report it and return.
TEST_CASE("a stray comma is a YAML syntax error at its position, not a hang") {
    struct Case {
        const char* yaml;
        int line;
    };
    for (const auto& [yaml, line] : {Case{",", 1}, Case{"gateway: {id: t}\n,\n", 2},
                                    Case{"gateway:\n  id: t\n, x\n", 3}}) {
        const auto diagnostics = diagnostics_of(yaml);
        INFO(dump(diagnostics));
        REQUIRE(diagnostics.size() == 1);
        CHECK(diagnostics[0].line == line);
        CHECK(diagnostics[0].column == 1);
        CHECK(diagnostics[0].message.find("YAML syntax error") != std::string::npos);
    }
}

TEST_CASE("empty files, several documents, a root that is not a map") {
    for (const auto* empty : {"", "# only a comment\n", "---\n"}) {
        const auto diagnostics = diagnostics_of(empty);
        INFO(dump(diagnostics));
        REQUIRE(diagnostics.size() == 1);
        CHECK(diagnostics[0].line == 1);
        CHECK(diagnostics[0].message.find("empty") != std::string::npos);
    }
    const auto two = diagnostics_of("gateway: {id: t}\n---\ngateway: {id: u}\n");
    INFO(dump(two));
    REQUIRE(two.size() == 1);
    CHECK(two[0].line == 3);
    CHECK(two[0].message.find("single document") != std::string::npos);

    CHECK_REPORTS("- a\n- b\n", "", 1, 1, "expected a map", "got a list");
}

TEST_CASE("unknown keys at every level name the key and list the allowed ones") {
    const char* yaml = R"(
gateway:
  id: t
  colour: red
modbus_tcp:
  listen_on: x
  rules:
    - action: deny
      unit: [1]
      registers: {from: 1, to: 2, too: 3}
lines:
  - name: a
    port: /dev/ttyS0
    baudrate: 9600
    rs485: {enable: true}
    offline_backoff: {initial: 1s, maximum: 2s}
    devices:
      - name: d
        type: hiwin-xeg
        address: 1
        unit_id: 1
        poll: {fastest: 1ms}
        adress: 2
      - name: m
        type: modbus
        address: 2
        unit_id: 2
        blocks:
          - {table: holding, address: 0, count: 1, size: 2}
upstreams:
  - name: r6
    host: r6
    units: [{unit_id: 50, name: r6, unit: 1}]
    reconnect_backoff: {init: 1s}
mqtt:
  url: tcp://x
  tls: {ca: x}
metrics_http: {port: 1}
extra: 1
)";
    CHECK_REPORTS(yaml, "gateway.colour", 3, 3, "unknown key 'colour'", "allowed keys here: id, log_level");
    CHECK_REPORTS(yaml, "modbus_tcp.listen_on", 5, 3, "unknown key 'listen_on'",
                  "listen, max_connections, idle_timeout, frame_timeout, max_connections_per_client, allow, rules");
    CHECK_REPORTS(yaml, "modbus_tcp.rules[0].unit", 8, 7, "did you mean 'units'?");
    CHECK_REPORTS(yaml, "modbus_tcp.rules[0].registers.too", 9, 35, "did you mean 'to'?", "from, to");
    CHECK_REPORTS(yaml, "lines[0].baudrate", 13, 5, "unknown key 'baudrate' (did you mean 'baud'?)");
    CHECK_REPORTS(yaml, "lines[0].rs485.enable", 14, 13, "did you mean 'enabled'?");
    CHECK_REPORTS(yaml, "lines[0].offline_backoff.maximum", 15, 36, "allowed keys here: initial, max");
    CHECK_REPORTS(yaml, "lines[0].devices[0].poll.fastest", 21, 16, "fast, slow, motion");
    CHECK_REPORTS(yaml, "lines[0].devices[0].adress", 22, 9, "did you mean 'address'?");
    CHECK_REPORTS(yaml, "lines[0].devices[1].blocks[0].size", 28, 52, "table, address, count, period, writable");
    CHECK_REPORTS(yaml, "upstreams[0].units[0].unit", 32, 37, "unit_id, upstream_unit, name");
    CHECK_REPORTS(yaml, "upstreams[0].reconnect_backoff.init", 33, 25, "did you mean 'initial'?", "initial, max");
    CHECK_REPORTS(yaml, "mqtt.url", 35, 3, "did you mean 'uri'?");
    CHECK_REPORTS(yaml, "mqtt.tls.ca", 36, 9, "ca_file, cert_file, key_file, verify");
    CHECK_REPORTS(yaml, "metrics_http.port", 37, 16, "allowed keys here: listen");
    CHECK_REPORTS(yaml, "extra", 38, 1, "gateway, modbus_tcp, lines, upstreams, mqtt, metrics_http");
    CHECK(diagnostics_of(yaml).size() == 16);  // nothing else is wrong in that file
}

TEST_CASE("duplicate keys are errors") {
    CHECK_REPORTS(R"(
gateway:
  id: a
  id: b
)",
                  "gateway.id", 3, 3, "duplicate key", "already set at line 2");
}

TEST_CASE("wrong kinds and types") {
    const char* yaml = R"(
gateway: [a]
modbus_tcp:
  listen: "0.0.0.0:502"
  max_connections: {a: 1}
lines:
  name: a
upstreams:
  - just-a-string
mqtt:
  deadband: {position_mm: [1]}
  qos: one
  enabled: yes
  keep_alive: 30
)";
    CHECK_REPORTS(yaml, "gateway", 1, 10, "expected a map", "got a list");
    CHECK_REPORTS(yaml, "modbus_tcp.listen", 3, 11, "expected a list of addresses", "got a single value");
    CHECK_REPORTS(yaml, "modbus_tcp.max_connections", 4, 20, "expected an integer, got a map");
    CHECK_REPORTS(yaml, "lines", 6, 3, "expected a list, got a map");
    CHECK_REPORTS(yaml, "upstreams[0]", 8, 5, "expected a map", "got a single value");
    CHECK_REPORTS(yaml, "mqtt.deadband.position_mm", 10, 27, "expected a number, got a list");
    CHECK_REPORTS(yaml, "mqtt.qos", 11, 8, "'one' is not an integer");
    CHECK_REPORTS(yaml, "mqtt.enabled", 12, 12, "'yes' is not a boolean; expected true or false");
    CHECK_REPORTS(yaml, "mqtt.keep_alive", 13, 15, "no unit", "30s");
    CHECK(diagnostics_of(yaml).size() == 9);
}

TEST_CASE("a key without a value") {
    CHECK_REPORTS(R"(
gateway:
  id:
)",
                  "gateway.id", 2, 3, "has no value", "remove the key");
}

TEST_CASE("missing required keys point at the enclosing map") {
    const char* yaml = R"(
lines:
  - port: /dev/ttyS0
    devices:
      - {name: d}
upstreams:
  - units: [{}]
)";
    CHECK_REPORTS(yaml, "gateway", 1, 1, "required section is missing", "gateway: { id:");
    CHECK_REPORTS(yaml, "lines[0].name", 2, 5, "required key is missing");
    CHECK_REPORTS(yaml, "lines[0].devices[0].type", 4, 9, "required key is missing",
                  "hiwin-xeg, excd203mb, wtec-rtu, wtec-ascii, modbus");
    CHECK_REPORTS(yaml, "lines[0].devices[0].address", 4, 9, "required key is missing");
    CHECK_REPORTS(yaml, "lines[0].devices[0].unit_id", 4, 9, "required key is missing", "1..247");
    CHECK_REPORTS(yaml, "upstreams[0].name", 6, 5, "required key is missing");
    CHECK_REPORTS(yaml, "upstreams[0].host", 6, 5, "required key is missing");
    CHECK_REPORTS(yaml, "upstreams[0].units[0].unit_id", 6, 13, "required key is missing");
    CHECK_REPORTS(yaml, "upstreams[0].units[0].name", 6, 13, "required key is missing");

    CHECK_REPORTS(R"(
gateway: {id: t}
lines:
  - name: a
)",
                  "lines[0].port", 3, 5, "required key is missing", "/dev/ttyUSB0");
    CHECK_REPORTS("gateway: {log_level: info}\n", "gateway.id", 1, 10, "required key is missing");
    CHECK_REPORTS(R"(
gateway: {id: t}
modbus_tcp:
  rules:
    - units: []
)",
                  "modbus_tcp.rules[0].action", 4, 7, "required key is missing", "allow or deny");
}

TEST_CASE("every error of a file is reported, in file order") {
    const char* yaml = R"(
gateway:
  id: bad id
modbus_tcp:
  max_connections: 0
lines:
  - name: a
    port: /dev/ttyS0
    baud: 12345
    devices:
      - {name: d, type: hiwin-xeg, address: 20, unit_id: 1}
      - {name: e, type: excd203mb, address: 3, unit_id: 1}
upstreams:
  - {name: r6, host: r6, port: 0, units: [{unit_id: 300, name: r6}]}
mqtt:
  qos: 5
  colour: blue
)";
    const auto diagnostics = diagnostics_of(yaml);
    INFO(dump(diagnostics));
    const std::vector<std::string> expected_keys{
        "gateway.id",
        "modbus_tcp.max_connections",
        "lines[0].baud",
        "lines[0].devices[0].address",
        "lines[0].devices[1].unit_id",
        "upstreams[0].port",
        "upstreams[0].units[0].unit_id",
        "mqtt.qos",
        "mqtt.colour",
    };
    REQUIRE(diagnostics.size() == expected_keys.size());
    for (std::size_t i = 0; i < expected_keys.size(); ++i) {
        CHECK(diagnostics[i].key == expected_keys[i]);
    }
    CHECK(std::is_sorted(diagnostics.begin(), diagnostics.end(), [](const Diagnostic& a, const Diagnostic& b) {
        return a.line != b.line ? a.line < b.line : a.column < b.column;
    }));
}

TEST_CASE("YAML merge keys and x- anchors at the top level") {
    const auto config = load_ok(R"(
x-gripper: &gripper {type: hiwin-xeg, command_ttl: 300ms, poll: {fast: 40ms}}
x-fast: &fast {max_age: 50ms, command_ttl: 900ms}
gateway: {id: t}
lines:
  - name: a
    port: /dev/ttyS0
    devices:
      - {<<: *gripper, name: g1, address: 1, unit_id: 1}
      - {<<: [*fast, *gripper], name: g2, address: 2, unit_id: 2, command_ttl: 200ms}
)");
    REQUIRE(config);
    const auto& devices = config->lines.at(0).devices;
    REQUIRE(devices.size() == 2);
    CHECK(devices[0].type == DeviceType::hiwin_xeg);
    CHECK(devices[0].command_ttl == std::chrono::milliseconds{300});
    CHECK(devices[0].poll.fast == std::chrono::milliseconds{40});
    CHECK(devices[1].type == DeviceType::hiwin_xeg);
    CHECK(devices[1].max_age == std::chrono::milliseconds{50});
    CHECK(devices[1].command_ttl == std::chrono::milliseconds{200});  // written in the map: wins

    // Earlier sources win over later ones.
    const auto order = load_ok(R"(
x-a: &a {command_ttl: 700ms}
x-b: &b {command_ttl: 800ms, type: hiwin-xeg}
gateway: {id: t}
lines: [{name: a, port: /dev/ttyS0, devices: [{<<: [*a, *b], name: g, address: 1, unit_id: 1}]}]
)");
    CHECK(order->lines.at(0).devices.at(0).command_ttl == std::chrono::milliseconds{700});

    // Keys brought in by a merge are checked like written ones, at the anchor's position.
    CHECK_REPORTS(R"(
x-bad: &bad {type: hiwin-xeg, colour: red}
gateway: {id: t}
lines: [{name: a, port: /dev/ttyS0, devices: [{<<: *bad, name: g, address: 1, unit_id: 1}]}]
)",
                  "lines[0].devices[0].colour", 1, 31, "unknown key 'colour'");
    CHECK_REPORTS("gateway: {id: t, <<: 5}\n", "gateway.<<", 1, 18, "a merge key needs a map");
    // x- keys are ignored only at the top level.
    CHECK_REPORTS("gateway: {id: t, x-note: 1}\n", "gateway.x-note", 1, 18, "unknown key 'x-note'");
}
