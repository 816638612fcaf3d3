// Loading: the shipped example and demo configurations, defaults, derived values,
// file handling and the diagnostic format.

#include <doctest/doctest.h>

#include <chrono>
#include <filesystem>
#include <fstream>

#include "config_test_support.hpp"

using namespace fieldbridge::config;
using namespace fieldbridge::config::test;
using namespace std::chrono_literals;
using fieldbridge::core::BusAddress;
using fieldbridge::core::UnitId;

namespace {

/// A directory under the system temp dir, removed when the test ends.
class TempDir {
public:
    TempDir() {
        path_ = std::filesystem::temp_directory_path() /
                ("fb-config-test-" + std::to_string(reinterpret_cast<std::uintptr_t>(this)) + "-" +
                 std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
        std::filesystem::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    [[nodiscard]] const std::filesystem::path& path() const { return path_; }
    std::filesystem::path write(const std::string& name, const std::string& content) const {
        const auto file = path_ / name;
        std::ofstream(file, std::ios::binary) << content;
        return file;
    }

private:
    std::filesystem::path path_;
};

}  // namespace

TEST_CASE("the example configuration loads and uses every section") {
    std::shared_ptr<const Config> config;
    try {
        config = load_config_file(FIELDBRIDGE_EXAMPLE_CONFIG);
    } catch (const ConfigError& e) {
        FAIL("example config does not load:\n" << e.what());
    }
    REQUIRE(config);
    CHECK(config->source_file == FIELDBRIDGE_EXAMPLE_CONFIG);
    CHECK(config->gateway.id == "cell-7");
    CHECK(config->modbus_tcp.rules.size() == 3);
    CHECK(config->modbus_tcp.allow.size() == 2);
    REQUIRE(config->lines.size() == 3);
    const auto& line = config->lines[0];
    REQUIRE(line.devices.size() == 4);
    CHECK(line.devices[0].type == DeviceType::hiwin_xeg);
    CHECK(line.devices[1].type == DeviceType::excd203mb);
    CHECK(line.devices[2].type == DeviceType::wtec_ascii);
    CHECK(line.devices[2].stroke == 20000U);
    CHECK(line.devices[3].type == DeviceType::modbus);
    CHECK(line.devices[3].blocks.size() == 3);
    CHECK(line.devices[3].word_order == WordOrder::low_first);
    CHECK(line.devices[3].points.points.size() == 6);
    CHECK(line.devices[3].points.alarms.size() == 2);
    CHECK(line.devices[3].points.points[0].type == fieldbridge::core::PointType::float32);
    CHECK(line.broadcast_unit == UnitId{100});
    CHECK(line.broadcast_share == 10U);
    CHECK(config->lines[1].devices.at(0).type == DeviceType::wtec_rtu);
    // A line behind a serial device server, with a paced meter.
    REQUIRE(config->lines[2].tcp.has_value());
    CHECK(config->lines[2].tcp->to_string() == "192.168.1.30:4001");
    CHECK(config->lines[2].devices.at(0).request_gap == std::chrono::milliseconds{20});
    CHECK(config->lines[2].devices.at(0).first_request_delay == std::chrono::seconds{1});
    REQUIRE(config->upstreams.size() == 1);
    CHECK(config->upstreams[0].units.at(0).unit_id == UnitId{50});
    CHECK(config->mqtt.enabled);
    CHECK(config->mqtt.deadband.at("position_mm") == doctest::Approx(0.05));
    REQUIRE(config->metrics_http.has_value());
    CHECK(config->metrics_http->listen.to_string() == "127.0.0.1:9102");
}

TEST_CASE("the demo configuration describes the demo cell") {
    std::shared_ptr<const Config> config;
    try {
        config = load_config_file(FIELDBRIDGE_DEMO_CONFIG);
    } catch (const ConfigError& e) {
        FAIL("demo config does not load:\n" << e.what());
    }
    REQUIRE(config);
    CHECK(config->gateway.id == "demo");
    REQUIRE(config->modbus_tcp.listen.size() == 1);
    CHECK(config->modbus_tcp.listen[0].to_string() == "127.0.0.1:1502");
    REQUIRE(config->lines.size() == 2);

    const auto& a = config->lines[0];
    CHECK(a.name == "line-a");
    CHECK(a.port == "/tmp/fieldbridge-demo/line-a");
    CHECK(a.broadcast_unit == UnitId{100});
    REQUIRE(a.devices.size() == 3);
    CHECK(a.devices[0].type == DeviceType::hiwin_xeg);
    CHECK(a.devices[0].address == BusAddress{2});
    CHECK(a.devices[0].unit_id == UnitId{1});
    CHECK(a.devices[1].type == DeviceType::excd203mb);
    CHECK(a.devices[1].address == BusAddress{3});
    CHECK(a.devices[1].unit_id == UnitId{2});
    CHECK(a.devices[2].type == DeviceType::wtec_ascii);
    CHECK(a.devices[2].address == BusAddress{5});
    CHECK(a.devices[2].unit_id == UnitId{3});
    CHECK(a.devices[2].stroke == 20000U);

    const auto& b = config->lines[1];
    CHECK(b.name == "line-b");
    CHECK(b.port == "/tmp/fieldbridge-demo/line-b");
    REQUIRE(b.devices.size() == 2);
    CHECK(b.devices[0].type == DeviceType::wtec_rtu);
    CHECK(b.devices[0].address == BusAddress{1});
    CHECK(b.devices[0].unit_id == UnitId{4});
    // The shipped example definition, found in config/devices beside the file.
    CHECK(b.devices[1].type == DeviceType::modbus);
    CHECK(b.devices[1].type_name == "example-thermostat");
    CHECK(b.devices[1].address == BusAddress{7});
    CHECK(b.devices[1].unit_id == UnitId{5});
    CHECK(b.devices[1].points.points.size() == 6);
    CHECK(b.devices[1].points.alarms.size() == 2);

    REQUIRE(config->upstreams.size() == 1);
    const auto& r6 = config->upstreams[0];
    CHECK(r6.name == "r6");
    CHECK(r6.host == "127.0.0.1");
    CHECK(r6.port == 15020);
    REQUIRE(r6.units.size() == 1);
    CHECK(r6.units[0].unit_id == UnitId{50});
    CHECK(r6.units[0].upstream_unit == UnitId{1});
    CHECK(r6.units[0].name == "r6");

    CHECK(config->mqtt.enabled);
    CHECK(config->mqtt.uris == std::vector<std::string>{"tcp://127.0.0.1:18830"});
    CHECK(config->mqtt.prefix == "fieldbridge/demo");
}

TEST_CASE("defaults are applied for everything left out") {
    const auto config = load_ok(R"(
gateway: {id: cell-1}
lines:
  - name: a
    port: /dev/ttyS0
    devices:
      - {name: g, type: hiwin-xeg, address: 1, unit_id: 1}
upstreams:
  - {name: r6, host: r6.local, units: [{unit_id: 50, name: robot}]}
)");
    REQUIRE(config);
    CHECK(config->gateway.log_level == LogLevel::info);

    const auto& tcp = config->modbus_tcp;
    REQUIRE(tcp.listen.size() == 1);
    CHECK(tcp.listen[0] == ListenAddress{"0.0.0.0", 502});
    CHECK(tcp.max_connections == 64);
    CHECK(tcp.idle_timeout == 60s);
    CHECK(tcp.frame_timeout == 5s);
    CHECK(config->mqtt.max_command_bytes == 16384);
    CHECK(config->mqtt.max_command_id_length == 128);
    CHECK(config->mqtt.max_queued_commands == 64);
    CHECK(config->mqtt.max_queued_command_bytes == 1024 * 1024);
    CHECK(config->mqtt.outbox_max_bytes == 4 * 1024 * 1024);
    CHECK(config->mqtt.outbox_max_messages == 512);
    CHECK(tcp.max_connections_per_client == 16);
    CHECK(tcp.allow.empty());
    CHECK(tcp.rules.empty());

    const auto& line = config->lines.at(0);
    CHECK(line.baud == 115200);
    CHECK(line.parity == Parity::none);
    CHECK(line.data_bits == 8);
    CHECK(line.stop_bits == 1);
    CHECK_FALSE(line.rs485.enabled);
    CHECK(line.rs485.rts_on_send);
    CHECK_FALSE(line.rs485.rts_after_send);
    CHECK(line.rs485.delay_before_send == 0ms);
    CHECK_FALSE(line.local_echo);
    CHECK(line.response_timeout == 100ms);
    CHECK(line.byte_timeout == 5ms);
    CHECK(line.turnaround == 0ms);
    CHECK(line.broadcast_delay == 100ms);
    CHECK_FALSE(line.precise_timing);
    CHECK(line.read_retries == 1);
    CHECK(line.offline_after == 3);
    CHECK(line.offline_backoff == Backoff{1s, 30s});
    CHECK_FALSE(line.broadcast_unit.has_value());
    CHECK(line.broadcast_share == 10U);

    const auto& device = line.devices.at(0);
    CHECK(device.max_age == 200ms);
    CHECK(device.command_ttl == 500ms);
    CHECK(device.delay_before_command == 0ms);
    CHECK(device.queue_limit == 16);
    CHECK(device.poll == PollConfig{50ms, 1s, 20ms});
    CHECK_FALSE(device.allow_protected);
    CHECK(device.mqtt_commands);
    CHECK(device.word_order == WordOrder::high_first);
    CHECK_FALSE(device.stroke.has_value());
    CHECK(device.blocks.empty());

    const auto& upstream = config->upstreams.at(0);
    CHECK(upstream.port == 502);
    CHECK(upstream.connect_timeout == 2s);
    CHECK(upstream.response_timeout == 1s);
    CHECK(upstream.reconnect_backoff == Backoff{500ms, 30s});
    CHECK(upstream.poll_period == 500ms);
    CHECK(upstream.command_ttl == 1s);
    CHECK(upstream.queue_limit == 32);
    CHECK(upstream.units.at(0).upstream_unit == UnitId{1});

    CHECK_FALSE(config->mqtt.enabled);  // no mqtt section: MQTT is off
    CHECK_FALSE(config->metrics_http.has_value());
}

TEST_CASE("mqtt defaults and derived values") {
    const auto config = load_ok(R"(
gateway: {id: cell-9}
mqtt:
metrics_http:
)");
    REQUIRE(config);
    const auto& mqtt = config->mqtt;
    CHECK(mqtt.enabled);  // the section is present
    CHECK(mqtt.uris == std::vector<std::string>{"tcp://127.0.0.1:1883"});
    CHECK(mqtt.client_id == "fieldbridge-cell-9");
    CHECK(mqtt.prefix == "fieldbridge/cell-9");
    CHECK(mqtt.username.empty());
    CHECK(mqtt.password.empty());
    CHECK(mqtt.qos == 1);
    CHECK(mqtt.keep_alive == 30s);
    CHECK(mqtt.clean_session);
    CHECK(mqtt.version == MqttVersion::v3_1_1);
    CHECK(mqtt.heartbeat == 60s);
    CHECK(mqtt.min_interval == 200ms);
    CHECK(mqtt.deadband.empty());
    CHECK(mqtt.diag_period == 10s);
    CHECK(mqtt.reconnect_backoff == Backoff{1s, 60s});
    CHECK(mqtt.tls.verify);
    CHECK_FALSE(mqtt.uses_tls());
    REQUIRE(config->metrics_http.has_value());
    CHECK(config->metrics_http->listen == ListenAddress{"127.0.0.1", 9102});

    const auto explicit_values = load_ok(R"(
gateway: {id: cell-9}
mqtt:
  enabled: false
  client_id: my-client
  prefix: plant/cell-9
  version: "5"
)");
    CHECK_FALSE(explicit_values->mqtt.enabled);
    CHECK(explicit_values->mqtt.client_id == "my-client");
    CHECK(explicit_values->mqtt.prefix == "plant/cell-9");
    CHECK(explicit_values->mqtt.version == MqttVersion::v5);
}

TEST_CASE("byte_timeout default follows the baud") {
    const auto config = load_ok(R"(
gateway: {id: t}
lines:
  - {name: slow, port: /dev/ttyS0, baud: 1200, response_timeout: 200ms}
  - {name: slow-set, port: /dev/ttyS1, baud: 1200, response_timeout: 200ms, byte_timeout: 20ms}
  - {name: fast, port: /dev/ttyS2, baud: 921600}
)");
    REQUIRE(config);
    // 3.5 characters of 10 bits at 1200 bit/s = 29.17 ms, rounded up.
    CHECK(config->lines.at(0).byte_timeout == 30ms);
    CHECK(config->lines.at(1).byte_timeout == 20ms);
    CHECK(config->lines.at(2).byte_timeout == 5ms);
    CHECK(config->lines.at(0).character_time() == std::chrono::nanoseconds{8'333'334});
    CHECK(config->lines.at(2).bits_per_character() == 10);
}

TEST_CASE("precise_timing default: on when the whole silence is shorter than the spin lead") {
    const auto config = load_ok(R"(
gateway: {id: t}
lines:
  - {name: a, port: /dev/ttyS0, baud: 115200}
  - {name: b, port: /dev/ttyS1, baud: 230400}
  - {name: c, port: /dev/ttyS2, baud: 921600}
  - {name: d, port: /dev/ttyS3, baud: 921600, turnaround: 1ms}
  - {name: e, port: /dev/ttyS4, baud: 921600, precise_timing: false}
)");
    REQUIRE(config);
    CHECK_FALSE(config->lines.at(0).precise_timing);  // 3.5 characters: 304 us
    CHECK(config->lines.at(1).precise_timing);        // 152 us
    CHECK(config->lines.at(2).precise_timing);        // 38 us
    CHECK_FALSE(config->lines.at(3).precise_timing);  // the turnaround gates: 1 ms
    CHECK_FALSE(config->lines.at(4).precise_timing);
}

TEST_CASE("explicit values override defaults; integers in hex; IPv6 listen") {
    const auto config = load_ok(R"(
gateway: {id: t, log_level: debug}
modbus_tcp:
  listen: ["[::1]:1502", "127.0.0.1:1502"]
  idle_timeout: 0ms
  frame_timeout: 750ms
  max_connections_per_client: 2
lines:
  - name: a
    port: /dev/ttyS0
    baud: 0x4B0
    parity: even
    data_bits: 7
    stop_bits: 2
    rs485: {enabled: true, rts_on_send: false, rts_after_send: true, delay_before_send: 1ms, delay_after_send: 2ms}
    local_echo: true
    precise_timing: true
    read_retries: 0
    devices:
      - {name: m, type: modbus, address: 0x10, unit_id: 0x20,
         blocks: [{table: discrete_inputs, address: 0x0010, count: 2000}, {table: holding, address: 0xFF83, count: 125, writable: true}]}
)");
    REQUIRE(config);
    CHECK(config->gateway.log_level == LogLevel::debug);
    CHECK(config->modbus_tcp.listen.at(0).host == "::1");
    CHECK(config->modbus_tcp.idle_timeout == 0ms);
    CHECK(config->modbus_tcp.frame_timeout == 750ms);
    CHECK(config->modbus_tcp.max_connections_per_client == 2);
    const auto& line = config->lines.at(0);
    CHECK(line.baud == 1200);
    CHECK(line.parity == Parity::even);
    CHECK(line.data_bits == 7);
    CHECK(line.stop_bits == 2);
    CHECK(line.bits_per_character() == 11);
    CHECK(line.rs485 == Rs485Config{true, false, true, 1ms, 2ms});
    CHECK(line.local_echo);
    CHECK(line.precise_timing);
    CHECK(line.read_retries == 0);
    const auto& device = line.devices.at(0);
    CHECK(device.address == BusAddress{0x10});
    CHECK(device.unit_id == UnitId{0x20});
    REQUIRE(device.blocks.size() == 2);
    CHECK(device.blocks[0].table == RegisterTable::discrete_inputs);
    CHECK(device.blocks[0].count == 2000);
    CHECK(device.blocks[0].period == 1s);
    CHECK_FALSE(device.blocks[0].writable);
    CHECK(device.blocks[1].address == 0xFF83);
    CHECK(device.blocks[1].writable);
}

TEST_CASE("a reload of the same text gives an equal Config; a change is seen per line") {
    const std::string text = R"(
gateway: {id: t}
lines:
  - {name: a, port: /dev/ttyS0, devices: [{name: g, type: hiwin-xeg, address: 1, unit_id: 1}]}
  - {name: b, port: /dev/ttyS1, devices: [{name: h, type: hiwin-xeg, address: 1, unit_id: 2}]}
)";
    const auto first = load_ok(text);
    const auto second = load_ok(text);
    CHECK(first->lines == second->lines);
    std::string changed = text;
    changed.replace(changed.find("unit_id: 2"), 10, "unit_id: 3");
    const auto third = load_ok(changed);
    CHECK(first->lines[0] == third->lines[0]);
    CHECK_FALSE(first->lines[1] == third->lines[1]);
}

TEST_CASE("files: unreadable path, relative TLS and password files") {
    SUBCASE("a missing file is one diagnostic without position") {
        try {
            (void)load_config_file("/nonexistent/fieldbridge.yaml");
            FAIL("expected ConfigError");
        } catch (const ConfigError& e) {
            REQUIRE(e.diagnostics().size() == 1);
            const auto& d = e.diagnostics()[0];
            CHECK(d.file == "/nonexistent/fieldbridge.yaml");
            CHECK(d.line == 0);
            CHECK(d.message.find("cannot open") != std::string::npos);
            CHECK(d.to_string().rfind("/nonexistent/fieldbridge.yaml: cannot open", 0) == 0);
        }
    }
    SUBCASE("relative paths resolve against the config file's directory") {
        const TempDir dir;
        dir.write("ca.pem", "ca");
        dir.write("client.pem", "cert");
        dir.write("secret", "s3cret\n");
        const auto file = dir.write("fb.yaml", R"(gateway: {id: t}
mqtt:
  uri: ssl://broker.local:8883
  username: gw
  password_file: secret
  tls: {ca_file: ca.pem, cert_file: client.pem}
)");
        const auto config = load_config_file(file);
        CHECK(config->mqtt.uses_tls());
        CHECK(config->mqtt.tls.ca_file == (dir.path() / "ca.pem").string());
        CHECK(config->mqtt.tls.cert_file == (dir.path() / "client.pem").string());
        CHECK(config->mqtt.password_file == (dir.path() / "secret").string());
        CHECK(config->mqtt.password == "s3cret");  // the trailing newline is not part of it
    }
}

TEST_CASE("diagnostic format") {
    CHECK(Diagnostic{"f.yaml", 3, 7, "lines[0].baud", "bad"}.to_string() == "f.yaml:3:7: lines[0].baud: bad");
    CHECK(Diagnostic{"f.yaml", 1, 2, "", "YAML syntax error: x"}.to_string() == "f.yaml:1:2: YAML syntax error: x");
    CHECK(Diagnostic{"f.yaml", 0, 0, "", "cannot open"}.to_string() == "f.yaml: cannot open");

    const ConfigError error({Diagnostic{"f", 1, 1, "a", "one"}, Diagnostic{"f", 2, 1, "b", "two"}});
    CHECK(std::string(error.what()) == "f:1:1: a: one\nf:2:1: b: two");
    CHECK(error.diagnostics().size() == 2);
}

TEST_CASE("enum spellings") {
    CHECK(to_string(DeviceType::hiwin_xeg) == "hiwin-xeg");
    CHECK(to_string(DeviceType::wtec_ascii) == "wtec-ascii");
    for (const auto type : {DeviceType::hiwin_xeg, DeviceType::excd203mb, DeviceType::wtec_rtu, DeviceType::wtec_ascii,
                            DeviceType::modbus}) {
        CHECK(fieldbridge::core::parse<DeviceType>(to_string(type)) == type);
    }
    CHECK_FALSE(fieldbridge::core::parse<DeviceType>("hiwin_xeg").has_value());
    CHECK(to_string(LogLevel::warning) == "warning");
    CHECK(to_string(MqttVersion::v5) == "5");
    CHECK(to_string(RegisterTable::discrete_inputs) == "discrete_inputs");
    CHECK(address_range(DeviceType::hiwin_xeg).max == 15);
    CHECK(address_range(DeviceType::excd203mb).max == 254);
    CHECK(broadcast_address(DeviceType::excd203mb) == BusAddress{0xFF});
    CHECK(broadcast_address(DeviceType::wtec_rtu) == BusAddress{0});
}
