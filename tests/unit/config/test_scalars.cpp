// Scalar conversions: integers, durations, booleans, numbers, network values and
// the MQTT URI.

#include <doctest/doctest.h>

#include <chrono>

#include "config/mqtt_uri.hpp"
#include "config/net_address.hpp"
#include "config/scalars.hpp"

using namespace fieldbridge::config;
using std::chrono::milliseconds;

TEST_CASE("integers: decimal and 0x hex only") {
    CHECK(*parse_integer("0").value == 0);
    CHECK(*parse_integer("502").value == 502);
    CHECK(*parse_integer("-3").value == -3);
    CHECK(*parse_integer("0x0600").value == 0x0600);
    CHECK(*parse_integer("0XfF").value == 255);
    CHECK(*parse_integer("007").value == 7);  // decimal, never octal
    CHECK(*parse_integer("9223372036854775807").value == INT64_MAX);

    for (const auto* bad : {"", "1.5", "0x", "0xG1", "12a", "+5", "1_000", "0b101", "-0x10", " 5", "five", "1e3"}) {
        INFO("text: '" << bad << "'");
        const auto parsed = parse_integer(bad);
        CHECK_FALSE(parsed);
        CHECK(parsed.error.find("integer") != std::string::npos);
    }
    const auto huge = parse_integer("9223372036854775808");
    CHECK_FALSE(huge);
    CHECK(huge.error.find("too large") != std::string::npos);
    CHECK_FALSE(parse_integer("0x10000000000000000"));
}

TEST_CASE("durations need a unit") {
    CHECK(*parse_duration("250ms").value == milliseconds{250});
    CHECK(*parse_duration("2s").value == milliseconds{2000});
    CHECK(*parse_duration("1min").value == milliseconds{60000});
    CHECK(*parse_duration("1.5s").value == milliseconds{1500});
    CHECK(*parse_duration("0.25min").value == milliseconds{15000});
    CHECK(*parse_duration("1h").value == milliseconds{3'600'000});
    CHECK(*parse_duration("24h").value == milliseconds{86'400'000});
    CHECK(*parse_duration("1.5h").value == milliseconds{5'400'000});
    CHECK(*parse_duration("0ms").value == milliseconds{0});
    CHECK(*parse_duration("10 ms").value == milliseconds{10});

    SUBCASE("a bare number says the unit is missing and shows how to write it") {
        const auto parsed = parse_duration("250");
        REQUIRE_FALSE(parsed);
        CHECK(parsed.error.find("no unit") != std::string::npos);
        CHECK(parsed.error.find("250ms") != std::string::npos);
    }
    SUBCASE("unknown unit") {
        const auto parsed = parse_duration("2d");
        REQUIRE_FALSE(parsed);
        CHECK(parsed.error.find("unknown unit 'd'") != std::string::npos);
        CHECK(parsed.error.find("ms, s, min or h") != std::string::npos);
        CHECK_FALSE(parse_duration("2hr"));
        CHECK_FALSE(parse_duration("5us"));
        CHECK_FALSE(parse_duration("5mins"));
        CHECK_FALSE(parse_duration("5 m s"));
    }
    SUBCASE("negative, fractional milliseconds, malformed, too long") {
        CHECK(parse_duration("-5ms").error.find("negative") != std::string::npos);
        CHECK(parse_duration("0.5ms").error.find("whole number of milliseconds") != std::string::npos);
        CHECK_FALSE(parse_duration("1.2.3s"));
        CHECK_FALSE(parse_duration("1.s"));
        CHECK_FALSE(parse_duration("ms"));
        CHECK_FALSE(parse_duration(""));
        CHECK_FALSE(parse_duration("s5"));
        CHECK(parse_duration("100000000min").error.find("too long") != std::string::npos);
    }
}

TEST_CASE("booleans are true or false only") {
    CHECK(*parse_bool("true").value);
    CHECK_FALSE(*parse_bool("false").value);
    for (const auto* bad : {"yes", "no", "on", "off", "1", "0", "True", "FALSE", ""}) {
        INFO("text: '" << bad << "'");
        const auto parsed = parse_bool(bad);
        CHECK_FALSE(parsed);
        CHECK(parsed.error.find("expected true or false") != std::string::npos);
    }
}

TEST_CASE("numbers") {
    CHECK(*parse_number("0.05").value == doctest::Approx(0.05));
    CHECK(*parse_number("2").value == doctest::Approx(2.0));
    CHECK(*parse_number("1e-3").value == doctest::Approx(0.001));
    CHECK(*parse_number("-1.5").value == doctest::Approx(-1.5));
    for (const auto* bad : {"", "nan", "inf", "0x10", "1,5", "abc", "1.0.0"}) {
        INFO("text: '" << bad << "'");
        CHECK_FALSE(parse_number(bad));
    }
}

TEST_CASE("format_duration uses the largest exact unit") {
    CHECK(format_duration(milliseconds{0}) == "0ms");
    CHECK(format_duration(milliseconds{250}) == "250ms");
    CHECK(format_duration(milliseconds{1500}) == "1500ms");
    CHECK(format_duration(milliseconds{2000}) == "2s");
    CHECK(format_duration(milliseconds{90000}) == "90s");
    CHECK(format_duration(milliseconds{120000}) == "2min");
    for (const auto text : {"0ms", "250ms", "2s", "90s", "2min"}) {
        CHECK(format_duration(*parse_duration(text).value) == text);
    }
}

TEST_CASE("listen addresses") {
    const auto v4 = parse_listen_address("0.0.0.0:502");
    REQUIRE(v4);
    CHECK(v4.value->host == "0.0.0.0");
    CHECK(v4.value->port == 502);
    CHECK_FALSE(v4.value->is_ipv6());
    CHECK(v4.value->to_string() == "0.0.0.0:502");

    const auto v6 = parse_listen_address("[::1]:1502");
    REQUIRE(v6);
    CHECK(v6.value->host == "::1");
    CHECK(v6.value->port == 1502);
    CHECK(v6.value->is_ipv6());
    CHECK(v6.value->to_string() == "[::1]:1502");

    CHECK(parse_listen_address("localhost:502").error.find("not an IPv4 address") != std::string::npos);
    CHECK(parse_listen_address("::1:502").error.find("needs brackets") != std::string::npos);
    CHECK(parse_listen_address("127.0.0.1").error.find("no port") != std::string::npos);
    CHECK(parse_listen_address("127.0.0.1:0").error.find("not a port") != std::string::npos);
    CHECK(parse_listen_address("127.0.0.1:65536").error.find("not a port") != std::string::npos);
    CHECK_FALSE(parse_listen_address("127.0.0.1:"));
    CHECK_FALSE(parse_listen_address("[::1]"));
    CHECK_FALSE(parse_listen_address("[::1]1502"));
    CHECK_FALSE(parse_listen_address("[zz::1]:1502"));
    CHECK_FALSE(parse_listen_address("256.0.0.1:502"));
    CHECK_FALSE(parse_listen_address(""));
}

TEST_CASE("CIDR networks") {
    const auto net = parse_cidr("10.0.0.0/8");
    REQUIRE(net);
    CHECK(net.value->prefix_length == 96 + 8);
    CHECK(net.value->text == "10.0.0.0/8");
    CHECK(net.value->contains(*parse_ip_address("10.200.3.4")));
    CHECK_FALSE(net.value->contains(*parse_ip_address("11.0.0.1")));
    CHECK_FALSE(net.value->contains(*parse_ip_address("::1")));
    CHECK(net.value->contains(ipv4_mapped(0x0A010203)));

    const auto host = parse_cidr("192.168.1.5");
    REQUIRE(host);
    CHECK(host.value->contains(*parse_ip_address("192.168.1.5")));
    CHECK_FALSE(host.value->contains(*parse_ip_address("192.168.1.6")));

    const auto any4 = parse_cidr("0.0.0.0/0");
    REQUIRE(any4);
    CHECK(any4.value->contains(*parse_ip_address("8.8.8.8")));
    CHECK_FALSE(any4.value->contains(*parse_ip_address("2001:db8::1")));  // IPv4 networks hold IPv4 only

    const auto v6 = parse_cidr("fd00::/8");
    REQUIRE(v6);
    CHECK(v6.value->contains(*parse_ip_address("fd12::5")));
    CHECK_FALSE(v6.value->contains(*parse_ip_address("fe80::1")));

    const auto odd_prefix = parse_cidr("10.0.0.0/12");
    REQUIRE(odd_prefix);
    CHECK(odd_prefix.value->contains(*parse_ip_address("10.15.255.255")));
    CHECK_FALSE(odd_prefix.value->contains(*parse_ip_address("10.16.0.0")));

    const auto host_bits = parse_cidr("10.1.2.3/8");
    REQUIRE_FALSE(host_bits);
    CHECK(host_bits.error.find("did you mean 10.0.0.0/8?") != std::string::npos);
    CHECK(parse_cidr("10.0.0.0/33").error.find("prefix length") != std::string::npos);
    CHECK(parse_cidr("fd00::/129").error.find("prefix length") != std::string::npos);
    CHECK_FALSE(parse_cidr("10.0.0.0/"));
    CHECK_FALSE(parse_cidr("10.0.0.0/x"));
    CHECK_FALSE(parse_cidr("10.0.0/8"));
    CHECK_FALSE(parse_cidr("plc.local/32"));
}

TEST_CASE("IPv4-mapped addresses") {
    const auto mapped = *parse_ip_address("::ffff:127.0.0.1");
    CHECK(is_ipv4_mapped(mapped));
    CHECK(mapped == ipv4_mapped(0x7F000001));
    CHECK(mapped == *parse_ip_address("127.0.0.1"));
    CHECK_FALSE(is_ipv4_mapped(*parse_ip_address("::1")));
}

TEST_CASE("host names") {
    for (const auto* good : {"r6.local", "192.168.1.20", "::1", "fe80::1", "a", "robot-7.cell.example"}) {
        INFO(good);
        CHECK(is_valid_host(good));
    }
    for (const auto* bad : {"", "r6:502", "-r6", "r6-", "a..b", "[::1]", "r6 cell", "tcp://r6"}) {
        INFO(bad);
        CHECK_FALSE(is_valid_host(bad));
    }
}

TEST_CASE("MQTT URIs") {
    const auto tcp = parse_mqtt_uri("tcp://127.0.0.1:18830");
    REQUIRE(tcp);
    CHECK(tcp.value->scheme == "tcp");
    CHECK(tcp.value->host == "127.0.0.1");
    CHECK(tcp.value->port == 18830);
    CHECK_FALSE(tcp.value->tls());

    CHECK(parse_mqtt_uri("tcp://broker").value->port == 1883);
    CHECK(parse_mqtt_uri("ssl://broker").value->port == 8883);
    CHECK(parse_mqtt_uri("ssl://broker").value->tls());
    CHECK(parse_mqtt_uri("wss://broker/mqtt").value->port == 443);
    CHECK(parse_mqtt_uri("wss://broker/mqtt").value->path == "/mqtt");
    CHECK(parse_mqtt_uri("ws://[::1]:9001/mqtt").value->host == "::1");
    CHECK(parse_mqtt_uri("ws://[::1]:9001/mqtt").value->port == 9001);

    CHECK(parse_mqtt_uri("mqtt://broker").error.find("unsupported scheme 'mqtt'") != std::string::npos);
    CHECK(parse_mqtt_uri("broker:1883").error.find("no scheme") != std::string::npos);
    CHECK(parse_mqtt_uri("tcp://broker/x").error.find("path") != std::string::npos);
    CHECK(parse_mqtt_uri("tcp://broker:0").error.find("invalid port") != std::string::npos);
    CHECK_FALSE(parse_mqtt_uri("tcp://broker:"));
    CHECK_FALSE(parse_mqtt_uri("tcp://:1883"));
    CHECK_FALSE(parse_mqtt_uri("tcp://[::1"));
    CHECK_FALSE(parse_mqtt_uri("tcp://[nope]:1883"));
}
