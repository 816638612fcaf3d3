// The sparkplug: section: defaults, the keys of issue 28, and every problem reported
// at file:line:col (docs/configuration.md, "sparkplug").
#include <cstdlib>
#include <filesystem>

#include "config/sparkplug_ids.hpp"
#include "config_test_support.hpp"
#include "temp_dir.hpp"

namespace {

using namespace fieldbridge::config;
using namespace fieldbridge::config::test;

/// Sets an environment variable for one scope.
class ScopedEnv {
public:
    ScopedEnv(const char* name, const char* value) : name_(name) {
        if (const char* old = std::getenv(name)) old_ = old;
        if (value == nullptr) {
            ::unsetenv(name);
        } else {
            ::setenv(name, value, 1);
        }
    }
    ~ScopedEnv() {
        if (old_) {
            ::setenv(name_, old_->c_str(), 1);
        } else {
            ::unsetenv(name_);
        }
    }
    ScopedEnv(const ScopedEnv&) = delete;
    ScopedEnv& operator=(const ScopedEnv&) = delete;

private:
    const char* name_;
    std::optional<std::string> old_;
};

}  // namespace

TEST_CASE("no sparkplug section: no Sparkplug edge node") {
    const auto config = load_ok(one_device_config("hiwin-xeg"));
    CHECK_FALSE(config->sparkplug);
}

TEST_CASE("sparkplug: the defaults") {
    const ScopedEnv env("STATE_DIRECTORY", nullptr);
    const auto config = load_ok(one_device_config("hiwin-xeg", "", "sparkplug:\n  servers: [tcp://127.0.0.1:1883]\n  group_id: plant1\n"));
    REQUIRE(config->sparkplug);
    const SparkplugConfig& s = *config->sparkplug;
    CHECK(s.servers == std::vector<std::string>{"tcp://127.0.0.1:1883"});
    CHECK(s.group_id == "plant1");
    CHECK(s.edge_node_id == "t");                   // gateway.id
    CHECK(s.client_id == "fieldbridge-t-sparkplug");  // not the JSON bridge's
    CHECK(s.primary_host_id.empty());
    CHECK(s.aliases);
    CHECK(s.keep_alive == std::chrono::seconds{30});
    CHECK(s.offline_buffer.max_messages == 20000);
    CHECK(s.offline_buffer.max_bytes == 16u * 1024 * 1024);
    CHECK(s.state_dir == "/var/lib/fieldbridge");
    CHECK_FALSE(s.uses_tls());
}

TEST_CASE("sparkplug: state_dir defaults to systemd's $STATE_DIRECTORY (its first path)") {
    const ScopedEnv env("STATE_DIRECTORY", "/var/lib/fieldbridge-a:/var/lib/other");
    const auto config = load_ok(one_device_config("hiwin-xeg", "", "sparkplug:\n  servers: [tcp://h:1883]\n  group_id: g\n"));
    CHECK(config->sparkplug->state_dir == "/var/lib/fieldbridge-a");
}

TEST_CASE("sparkplug: every key") {
    fieldbridge::test::TempDir dir;
    const std::string yaml = one_device_config(
        "hiwin-xeg", "",
        "sparkplug:\n"
        "  servers: [tcp://a:1883, ssl://b:8883]\n"
        "  client_id: gw-spb\n"
        "  group_id: plant1\n"
        "  edge_node_id: edge-7\n"
        "  primary_host_id: scada\n"
        "  username: node\n"
        "  password: pw\n"
        "  tls: {verify: false}\n"
        "  keep_alive: 10s\n"
        "  aliases: false\n"
        "  offline_buffer: {max_messages: 100, max_bytes: 1048576}\n"
        "  state_dir: " + dir.path().string() + "\n");
    const auto diagnostics = diagnostics_of(yaml);
    INFO(dump(diagnostics));
    REQUIRE(diagnostics.empty());
    const auto config = load_ok(yaml);
    const SparkplugConfig& s = *config->sparkplug;
    CHECK(s.servers == std::vector<std::string>{"tcp://a:1883", "ssl://b:8883"});
    CHECK(s.client_id == "gw-spb");
    CHECK(s.edge_node_id == "edge-7");
    CHECK(s.primary_host_id == "scada");
    CHECK(s.username == "node");
    CHECK(s.password == "pw");
    CHECK_FALSE(s.tls.verify);
    CHECK(s.keep_alive == std::chrono::seconds{10});
    CHECK_FALSE(s.aliases);
    CHECK(s.offline_buffer.max_messages == 100);
    CHECK(s.offline_buffer.max_bytes == 1048576);
    CHECK(s.state_dir == dir.path().string());
    CHECK(s.uses_tls());
}

TEST_CASE("sparkplug: servers and group_id are required") {
    const std::string yaml = one_device_config("hiwin-xeg", "", "sparkplug:\n  aliases: true\n");
    CHECK_REPORTS(yaml, "sparkplug.servers", 2, 3, "required key is missing", "list of servers");
    CHECK_REPORTS(yaml, "sparkplug.group_id", 2, 3, "required key is missing", "group_id");
}

TEST_CASE("sparkplug: bad values are reported where they are") {
    const std::string yaml = R"(
sparkplug:
  servers: [ws://a:80, "mqtt://b", tcp://ok:1883]
  client_id: "has space"
  group_id: "plant/1"
  edge_node_id: "e+"
  primary_host_id: "#"
  password: secret
  tls: {ca_file: /nonexistent/ca.pem}
  keep_alive: 1500ms
  offline_buffer: {max_messages: 0, max_bytes: 10}
  state_dir: /nonexistent/state
gateway: {id: t}
lines:
  - name: a
    port: /dev/ttyS0
    devices:
      - {name: d, type: hiwin-xeg, address: 3, unit_id: 1}
)";
    CHECK_REPORTS(yaml, "sparkplug.servers[0]", 2, 13, "a Sparkplug server is tcp:// or ssl://");
    CHECK_REPORTS(yaml, "sparkplug.servers[1]", 2, 24, "unsupported scheme 'mqtt'");
    CHECK_REPORTS(yaml, "sparkplug.client_id", 3, 14, "not a usable client id");
    CHECK_REPORTS(yaml, "sparkplug.group_id", 4, 13, "contains +, / or #", "Sparkplug group_id");
    CHECK_REPORTS(yaml, "sparkplug.edge_node_id", 5, 17, "contains +, / or #", "edge_node_id");
    CHECK_REPORTS(yaml, "sparkplug.primary_host_id", 6, 20, "contains +, / or #");
    CHECK_REPORTS(yaml, "sparkplug.password", 7, 13, "a password needs a username in MQTT 3.1.1");
    CHECK_REPORTS(yaml, "sparkplug.tls.ca_file", 8, 18, "file not found");
    CHECK_REPORTS(yaml, "sparkplug.tls", 8, 8, "TLS settings need an ssl:// server");
    CHECK_REPORTS(yaml, "sparkplug.keep_alive", 9, 15, "not whole seconds");
    CHECK_REPORTS(yaml, "sparkplug.offline_buffer.max_messages", 10, 34, "expected 1..1000000");
    CHECK_REPORTS(yaml, "sparkplug.offline_buffer.max_bytes", 10, 48, "out of range");
    CHECK_REPORTS(yaml, "sparkplug.state_dir", 11, 14, "not an existing directory");
}

TEST_CASE("sparkplug: an unknown key is reported") {
    const std::string yaml = one_device_config("hiwin-xeg", "", "sparkplug:\n  servers: [tcp://h:1883]\n  group_id: g\n  version: 5\n");
    const auto diagnostics = diagnostics_of(yaml);
    CHECK(find_diagnostic(diagnostics, "sparkplug.version"));
}

TEST_CASE("sparkplug: the client id may not be the JSON bridge's") {
    const std::string yaml = one_device_config(
        "hiwin-xeg", "", "mqtt: {client_id: same}\nsparkplug:\n  servers: [tcp://h:1883]\n  group_id: g\n  client_id: same\n");
    CHECK_REPORTS(yaml, "sparkplug.client_id", 5, 14, "is mqtt.client_id too");
}

TEST_CASE("sparkplug: a UTF-8 group is fine") {
    CHECK(load_ok(one_device_config("hiwin-xeg", "", "sparkplug:\n  servers: [tcp://h:1883]\n  group_id: \"Werk-S\xc3\xbc" "d\"\n"))
              ->sparkplug->group_id == "Werk-S\xc3\xbc" "d");
}

TEST_CASE("the Sparkplug ID rules (tck-id-topic-structure-namespace-valid-group-id, -valid-edge-node-id, -valid-device-id)") {
    CHECK_FALSE(sparkplug_id_problem("plant1"));
    CHECK_FALSE(sparkplug_id_problem("Werk S\xc3\xbc" "d.2"));
    CHECK(sparkplug_id_problem(""));
    CHECK(sparkplug_id_problem("a+b"));
    CHECK(sparkplug_id_problem("a/b"));
    CHECK(sparkplug_id_problem("a#"));
    CHECK(sparkplug_id_problem(std::string_view("a\0b", 3)));
    CHECK(*sparkplug_id_problem("a\xff") == "is not valid UTF-8");
    CHECK(sparkplug_id_problem("\xc3"));          // cut sequence
    CHECK(sparkplug_id_problem("\xc0\xaf"));      // overlong
}
