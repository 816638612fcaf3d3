// Lines behind serial device servers (issue 27): `port: tcp://host:port`, the options
// that apply to one transport only, per-device pacing, and one line per endpoint.

#include <doctest/doctest.h>

#include <string>

#include "config_test_support.hpp"

using namespace fieldbridge::config;
using namespace fieldbridge::config::test;

namespace {

/// One line on @p port with @p extra line keys and one XEG gripper with @p device_extra.
std::string line_on(std::string_view port, std::string_view extra = "", std::string_view device_extra = "") {
    return "gateway: {id: t}\n"
           "lines:\n"
           "  - name: a\n"
           "    port: " +
           std::string(port) + "\n" + std::string(extra) +
           "    devices:\n"
           "      - {name: d, type: hiwin-xeg, address: 1, unit_id: 1" +
           std::string(device_extra) + "}\n";
}

/// A diagnostic for @p key whose message holds every fragment.
void check_key(const std::string& yaml, std::string_view key, std::initializer_list<std::string_view> fragments) {
    const auto diagnostics = diagnostics_of(yaml);
    INFO("diagnostics:\n" << dump(diagnostics));
    const auto found = find_diagnostic(diagnostics, key);
    REQUIRE_MESSAGE(found.has_value(), "no diagnostic for key '" << std::string(key) << "'");
    for (const auto fragment : fragments) {
        CHECK_MESSAGE(found->message.find(fragment) != std::string::npos,
                      "message lacks '" << std::string(fragment) << "'");
    }
}

}  // namespace

TEST_CASE("tcp ports: IPv4, IPv6 in brackets and host names are read into the line's endpoint") {
    const auto v4 = load_ok(line_on("tcp://192.168.1.20:4001"));
    REQUIRE(v4->lines[0].tcp.has_value());
    CHECK(v4->lines[0].tcp->host == "192.168.1.20");
    CHECK(v4->lines[0].tcp->port == 4001);
    const auto v6 = load_ok(line_on("\"tcp://[fd00::7]:4001\""));
    REQUIRE(v6->lines[0].tcp.has_value());
    CHECK(v6->lines[0].tcp->host == "fd00::7");
    CHECK(v6->lines[0].tcp->to_string() == "[fd00::7]:4001");
    const auto named = load_ok(line_on("tcp://nport-3.cell:950"));
    REQUIRE(named->lines[0].tcp.has_value());
    CHECK(named->lines[0].tcp->host == "nport-3.cell");
    // The defaults: the frame gap as byte_timeout's, the upstreams' kind of back-off.
    CHECK(named->lines[0].tcp_frame_gap == std::chrono::milliseconds{5});
    CHECK(named->lines[0].connect_timeout == std::chrono::seconds{2});
    CHECK(named->lines[0].reconnect_backoff.max == std::chrono::milliseconds{500});
    const auto serial = load_ok(line_on("/dev/ttyS0"));
    CHECK_FALSE(serial->lines[0].tcp.has_value());
}

TEST_CASE("tcp ports: a malformed endpoint says what was expected") {
    check_key(line_on("tcp://192.168.1.20"), "lines[0].port", {"has no port", "tcp://HOST:PORT"});
    check_key(line_on("tcp://192.168.1.20:0"), "lines[0].port", {"is not a port", "1..65535"});
    check_key(line_on("tcp://fd00::7:4001"), "lines[0].port", {"needs brackets"});
    check_key(line_on("\"tcp://[fd00::zz]:4001\""), "lines[0].port", {"is not an IPv6 address"});
    check_key(line_on("tcp://bad_host!:4001"), "lines[0].port", {"is not a host name"});
}

TEST_CASE("tcp ports: serial-only options are errors that say why") {
    check_key(line_on("tcp://10.0.0.5:4001", "    rs485: {enabled: true}\n"), "lines[0].rs485",
              {"does not apply to a tcp:// port", "device server"});
    check_key(line_on("tcp://10.0.0.5:4001", "    local_echo: true\n"), "lines[0].local_echo",
              {"does not apply to a tcp:// port"});
    check_key(line_on("tcp://10.0.0.5:4001", "    byte_timeout: 5ms\n"), "lines[0].byte_timeout",
              {"use tcp_frame_gap"});
    check_key(line_on("tcp://10.0.0.5:4001", "    low_latency: true\n"), "lines[0].low_latency", {});
}

TEST_CASE("tcp ports: tcp-only options on a serial port are errors") {
    check_key(line_on("/dev/ttyS0", "    tcp_frame_gap: 5ms\n"), "lines[0].tcp_frame_gap", {"tcp:// ports only"});
    check_key(line_on("/dev/ttyS0", "    connect_timeout: 1s\n"), "lines[0].connect_timeout", {"tcp:// ports only"});
    check_key(line_on("/dev/ttyS0", "    reconnect_backoff: {initial: 1s, max: 2s}\n"), "lines[0].reconnect_backoff",
              {"tcp:// ports only", "offline_backoff"});
}

TEST_CASE("tcp ports: timing keys are read and checked against the far side's baud") {
    const auto config = load_ok(line_on("tcp://10.0.0.5:4001",
                                        "    baud: 9600\n    tcp_frame_gap: 20ms\n    request_gap: 10ms\n"
                                        "    connect_timeout: 500ms\n    reconnect_backoff: {initial: 100ms, max: 400ms}\n"));
    const auto& line = config->lines[0];
    CHECK(line.tcp_frame_gap == std::chrono::milliseconds{20});
    CHECK(line.request_gap == std::chrono::milliseconds{10});
    CHECK(line.connect_timeout == std::chrono::milliseconds{500});
    CHECK(line.reconnect_backoff.initial == std::chrono::milliseconds{100});
    CHECK(line.reconnect_backoff.max == std::chrono::milliseconds{400});
    // At 1200 bit/s 1.5 characters take 13.75 ms: a 5 ms gap would cut replies.
    check_key(line_on("tcp://10.0.0.5:4001", "    baud: 1200\n    tcp_frame_gap: 5ms\n"), "lines[0].tcp_frame_gap",
              {"shorter than the 1.5-character gap"});
    check_key(line_on("tcp://10.0.0.5:4001", "    request_gap: 2s\n"), "lines[0].request_gap", {"out of range"});
    check_key(line_on("tcp://10.0.0.5:4001", "    connect_timeout: 1ms\n"), "lines[0].connect_timeout", {"out of range"});
}

TEST_CASE("pacing: request_gap and first_request_delay per device, on any line") {
    const auto config =
        load_ok(line_on("/dev/ttyS0", "", ", request_gap: 50ms, first_request_delay: 2s"));
    CHECK(config->lines[0].devices[0].request_gap == std::chrono::milliseconds{50});
    CHECK(config->lines[0].devices[0].first_request_delay == std::chrono::seconds{2});
    check_key(line_on("tcp://10.0.0.5:4001", "", ", request_gap: 2min"), "lines[0].devices[0].request_gap",
              {"out of range"});
}

TEST_CASE("tcp ports: one line per device server endpoint, host names compared without case") {
    const std::string yaml = "gateway: {id: t}\n"
                             "lines:\n"
                             "  - name: a\n"
                             "    port: tcp://NPort-3:4001\n"
                             "    devices: [{name: d, type: hiwin-xeg, address: 1, unit_id: 1}]\n"
                             "  - name: b\n"
                             "    port: tcp://nport-3:4001\n"
                             "    devices: [{name: e, type: hiwin-xeg, address: 1, unit_id: 2}]\n";
    check_key(yaml, "lines[1].port", {"device server endpoint"});
    const std::string two_ports = "gateway: {id: t}\n"
                                  "lines:\n"
                                  "  - name: a\n"
                                  "    port: tcp://nport-3:4001\n"
                                  "    devices: [{name: d, type: hiwin-xeg, address: 1, unit_id: 1}]\n"
                                  "  - name: b\n"
                                  "    port: tcp://nport-3:4002\n"
                                  "    devices: [{name: e, type: hiwin-xeg, address: 1, unit_id: 2}]\n";
    CHECK(diagnostics_of(two_ports).empty());
}
