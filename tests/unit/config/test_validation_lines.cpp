// Lines and devices: serial settings, timing at the baud, addresses per type,
// type-specific keys, register blocks, and uniqueness across the config.

#include <doctest/doctest.h>

#include <chrono>
#include <filesystem>
#include <fstream>

#include "config_test_support.hpp"

using namespace fieldbridge::config;
using namespace fieldbridge::config::test;

namespace {

/// One line with one device; @p extra is appended to the device (lines 10+).
/// Positions: line 8 "address", line 9 "unit_id", values at column 18; the
/// device map starts at 6:9.
std::string one_device(std::string_view type, std::string_view address, std::string_view extra = "",
                       std::string_view unit_id = "1") {
    std::string yaml = "gateway: {id: t}\n"
                       "lines:\n"
                       "  - name: a\n"
                       "    port: /dev/ttyS0\n"
                       "    devices:\n"
                       "      - name: d\n"
                       "        type: " +
                       std::string(type) + "\n        address: " + std::string(address) +
                       "\n        unit_id: " + std::string(unit_id) + "\n";
    yaml += extra;
    return yaml;
}

const std::string modbus_blocks = "        blocks: [{table: holding, address: 0, count: 1}]\n";

std::string modbus_blocks_for(std::string_view type) { return type == "modbus" ? modbus_blocks : std::string(); }

}  // namespace

TEST_CASE("device addresses follow the type's range") {
    CHECK(diagnostics_of(one_device("hiwin-xeg", "15")).empty());
    CHECK(diagnostics_of(one_device("excd203mb", "254")).empty());
    CHECK(diagnostics_of(one_device("wtec-rtu", "253")).empty());
    CHECK(diagnostics_of(one_device("wtec-ascii", "253", "        stroke: 20000\n")).empty());
    CHECK(diagnostics_of(one_device("modbus", "247", modbus_blocks)).empty());

    CHECK_REPORTS(one_device("hiwin-xeg", "16"), "lines[0].devices[0].address", 8, 18,
                  "16 is outside the hiwin-xeg address range", "expected 1..15 for hiwin-xeg");
    CHECK_REPORTS(one_device("excd203mb", "255"), "lines[0].devices[0].address", 8, 18,
                  "0xFF (255) is the EXCD203MB broadcast address", "expected 1..254");
    CHECK_REPORTS(one_device("excd203mb", "0xFF"), "lines[0].devices[0].address", 8, 18, "broadcast address");
    CHECK_REPORTS(one_device("wtec-rtu", "254"), "lines[0].devices[0].address", 8, 18, "expected 1..253 for wtec-rtu");
    CHECK_REPORTS(one_device("wtec-ascii", "300", "        stroke: 1\n"), "lines[0].devices[0].address", 8, 18,
                  "expected 1..253");
    CHECK_REPORTS(one_device("modbus", "248", modbus_blocks), "lines[0].devices[0].address", 8, 18,
                  "expected 1..247 for modbus");
    CHECK_REPORTS(one_device("modbus", "-1", modbus_blocks), "lines[0].devices[0].address", 8, 18, "outside");
    for (const auto* type : {"hiwin-xeg", "excd203mb", "wtec-rtu", "modbus"}) {
        INFO(type);
        CHECK_REPORTS(one_device(type, "0", modbus_blocks_for(type)), "lines[0].devices[0].address", 8, 18,
                      "0 is the broadcast address and cannot be a device address");
    }
}

TEST_CASE("unit IDs are 1..247") {
    CHECK_REPORTS(one_device("hiwin-xeg", "1", "", "0"), "lines[0].devices[0].unit_id", 9, 18,
                  "0 is out of range; expected 1..247");
    CHECK_REPORTS(one_device("hiwin-xeg", "1", "", "248"), "lines[0].devices[0].unit_id", 9, 18, "expected 1..247");
    CHECK_REPORTS(one_device("hiwin-xeg", "1", "", "0x100"), "lines[0].devices[0].unit_id", 9, 18, "256 is out of range");
}

TEST_CASE("type-specific keys") {
    SUBCASE("stroke: required for wtec-ascii, refused elsewhere") {
        CHECK_REPORTS(one_device("wtec-ascii", "5"), "lines[0].devices[0].stroke", 6, 9, "required key is missing",
                      "encoder counts");
        CHECK_REPORTS(one_device("hiwin-xeg", "5", "        stroke: 100\n"), "lines[0].devices[0].stroke", 10, 17,
                      "stroke applies only to wtec-ascii", "this device is hiwin-xeg");
        CHECK_REPORTS(one_device("wtec-ascii", "5", "        stroke: 0\n"), "lines[0].devices[0].stroke", 10, 17,
                      "expected 1..2147483647");
    }
    SUBCASE("word_order: excd203mb and modbus only") {
        CHECK(diagnostics_of(one_device("excd203mb", "3", "        word_order: low_first\n")).empty());
        CHECK(diagnostics_of(one_device("modbus", "3", "        word_order: low_first\n" + modbus_blocks)).empty());
        for (const auto* type : {"hiwin-xeg", "wtec-rtu"}) {
            INFO(type);
            CHECK_REPORTS(one_device(type, "3", "        word_order: low_first\n"), "lines[0].devices[0].word_order",
                          10, 21, "word_order applies only to excd203mb and modbus");
        }
        CHECK_REPORTS(one_device("excd203mb", "3", "        word_order: middle\n"), "lines[0].devices[0].word_order",
                      10, 21, "expected one of: high_first, low_first");
    }
    SUBCASE("blocks: required for modbus, refused elsewhere") {
        CHECK_REPORTS(one_device("modbus", "3"), "lines[0].devices[0].blocks", 6, 9, "required key is missing",
                      "register blocks");
        CHECK_REPORTS(one_device("modbus", "3", "        blocks: []\n"), "lines[0].devices[0].blocks", 10, 17,
                      "is empty");
        CHECK_REPORTS(one_device("hiwin-xeg", "3", modbus_blocks), "lines[0].devices[0].blocks", 10, 17,
                      "blocks apply only to generic modbus devices");
        CHECK_REPORTS(one_device("modbus", "3", "        poll: {fast: 1s}\n" + modbus_blocks),
                      "lines[0].devices[0].poll", 10, 15, "blocks[].period");
    }
    SUBCASE("unknown type") {
        CHECK_REPORTS(one_device("hiwin_xeg", "3"), "lines[0].devices[0].type", 7, 15, "'hiwin_xeg' is not a built-in type",
                      "did you mean 'hiwin-xeg'?", "no device definition hiwin_xeg.yaml was found",
                      "hiwin-xeg, excd203mb, wtec-rtu, wtec-ascii, modbus");
    }
}

TEST_CASE("register blocks: limits, overlap, read-only tables, required keys") {
    CHECK_REPORTS(one_device("modbus", "3",
                             "        blocks:\n"
                             "          - table: holding\n"
                             "            address: 0\n"
                             "            count: 126\n"),
                  "lines[0].devices[0].blocks[0].count", 13, 20, "126 is out of range", "1..125 registers");
    CHECK_REPORTS(one_device("modbus", "3", "        blocks: [{table: coils, address: 0, count: 2001}]\n"),
                  "lines[0].devices[0].blocks[0].count", 10, 52, "1..2000 bits");
    CHECK(diagnostics_of(one_device("modbus", "3", "        blocks: [{table: coils, address: 0, count: 2000}]\n"))
              .empty());
    CHECK_REPORTS(one_device("modbus", "3", "        blocks: [{table: input, address: 0, count: 0}]\n"),
                  "lines[0].devices[0].blocks[0].count", 10, 52, "0 is out of range");
    CHECK_REPORTS(one_device("modbus", "3", "        blocks: [{table: input, address: 0xFFFF, count: 2}]\n"),
                  "lines[0].devices[0].blocks[0].count", 10, 57, "runs past register 0xFFFF");
    CHECK_REPORTS(one_device("modbus", "3", "        blocks: [{table: input, address: 0x10000, count: 1}]\n"),
                  "lines[0].devices[0].blocks[0].address", 10, 42, "expected 0..65535");
    CHECK_REPORTS(one_device("modbus", "3",
                             "        blocks: [{table: input, address: 0, count: 1, writable: true}]\n"),
                  "lines[0].devices[0].blocks[0].writable", 10, 65, "read-only", "table: holding");
    CHECK_REPORTS(one_device("modbus", "3", "        blocks: [{table: holding, address: 0, count: 1, period: 0ms}]\n"),
                  "lines[0].devices[0].blocks[0].period", 10, 65, "expected 1ms..60min");

    const std::string overlap = one_device("modbus", "3",
                                           "        blocks:\n"
                                           "          - {table: holding, address: 0x10, count: 10}\n"
                                           "          - {table: input, address: 0x10, count: 10}\n"
                                           "          - {table: holding, address: 0x1A, count: 2}\n"
                                           "          - {table: holding, address: 0x19, count: 2}\n");
    CHECK_REPORTS(overlap, "lines[0].devices[0].blocks[3]", 14, 13, "holding 0x0019-0x001A overlaps",
                  "lines[0].devices[0].blocks[0] (0x0010-0x0019)");
    const auto diagnostics = diagnostics_of(overlap);
    INFO(dump(diagnostics));
    CHECK(diagnostics.size() == 2);  // blocks[3] overlaps blocks[0] and blocks[2]; [1] is another table
    CHECK_FALSE(find_diagnostic(diagnostics, "lines[0].devices[0].blocks[1]").has_value());
    CHECK_FALSE(find_diagnostic(diagnostics, "lines[0].devices[0].blocks[2]").has_value());

    const std::string missing = one_device("modbus", "3", "        blocks:\n          - {period: 1s}\n");
    CHECK_REPORTS(missing, "lines[0].devices[0].blocks[0].table", 11, 13, "required key is missing");
    CHECK_REPORTS(missing, "lines[0].devices[0].blocks[0].address", 11, 13, "required key is missing");
    CHECK_REPORTS(missing, "lines[0].devices[0].blocks[0].count", 11, 13, "required key is missing");
}

TEST_CASE("device values out of range") {
    const std::string yaml = one_device("hiwin-xeg", "1",
                                        "        max_age: 61min\n"
                                        "        command_ttl: 2min\n"
                                        "        delay_before_command: 2s\n"
                                        "        queue_limit: 0\n"
                                        "        poll: {fast: 0ms, slow: 1s, motion: 61min}\n");
    CHECK_REPORTS(yaml, "lines[0].devices[0].max_age", 10, 18, "61min is out of range", "expected 0ms..60min");
    CHECK_REPORTS(yaml, "lines[0].devices[0].command_ttl", 11, 22, "expected 1ms..1min");
    CHECK_REPORTS(yaml, "lines[0].devices[0].delay_before_command", 12, 31, "expected 0ms..1s");
    CHECK_REPORTS(yaml, "lines[0].devices[0].queue_limit", 13, 22, "expected 1..1024");
    CHECK_REPORTS(yaml, "lines[0].devices[0].poll.fast", 14, 22, "expected 1ms..60min");
    CHECK_REPORTS(yaml, "lines[0].devices[0].poll.motion", 14, 45, "expected 1ms..60min");
    CHECK(diagnostics_of(yaml).size() == 6);
}

TEST_CASE("command_ttl shorter than the line's response_timeout") {
    CHECK_REPORTS(one_device("hiwin-xeg", "1", "        command_ttl: 50ms\n"), "lines[0].devices[0].command_ttl", 10,
                  22, "shorter than the line's response_timeout (100ms)", "expected at least 100ms");
    CHECK(diagnostics_of(one_device("hiwin-xeg", "1", "        command_ttl: 100ms\n")).empty());
}

TEST_CASE("serial settings") {
    const char* yaml = R"(
gateway: {id: t}
lines:
  - name: a
    port: /dev/ttyS0
    baud: 115000
    data_bits: 9
    stop_bits: 3
    parity: mark
    rs485: {delay_before_send: 2s}
    precise_timing: spin
)";
    CHECK_REPORTS(yaml, "lines[0].baud", 5, 11, "115000 is not a standard rate", "9600, 19200");
    CHECK_REPORTS(yaml, "lines[0].data_bits", 6, 16, "expected 7 or 8");
    CHECK_REPORTS(yaml, "lines[0].stop_bits", 7, 16, "expected 1 or 2");
    CHECK_REPORTS(yaml, "lines[0].parity", 8, 13, "expected one of: none, even, odd");
    CHECK_REPORTS(yaml, "lines[0].rs485.delay_before_send", 9, 32, "expected 0ms..1s");
    CHECK_REPORTS(yaml, "lines[0].precise_timing", 10, 21, "'spin' is not a boolean; expected true or false");

    CHECK_REPORTS("gateway: {id: t}\nlines: [{name: a, port: ttyS0}]\n", "lines[0].port", 2, 25,
                  "not an absolute path");
    CHECK_REPORTS("gateway: {id: t}\nlines: [{name: line a, port: /dev/ttyS0}]\n", "lines[0].name", 2, 16,
                  "'line a' is not a valid name", "A-Z a-z 0-9 _ -");
}

TEST_CASE("timeouts must make sense at the baud") {
    const char* slow = R"(
gateway: {id: t}
lines:
  - name: a
    port: /dev/ttyS0
    baud: 1200
    response_timeout: 20ms
    byte_timeout: 10ms
)";
    // 8N1 = 10 bits: one character at 1200 bit/s is 8.33 ms.
    CHECK_REPORTS(slow, "lines[0].response_timeout", 6, 23, "3.5-character silence at 1200 bit/s 8N1 (29.17 ms)",
                  "expected at least 30ms");
    CHECK_REPORTS(slow, "lines[0].byte_timeout", 7, 19, "1.5-character gap", "(12.50 ms)", "expected at least 13ms");

    // 8E2 = 12 bits at 9600 bit/s: 3.5 characters = 4.375 ms.
    CHECK_REPORTS(R"(
gateway: {id: t}
lines:
  - {name: a, port: /dev/ttyS0, baud: 9600, parity: even, stop_bits: 2, response_timeout: 4ms}
)",
                  "lines[0].response_timeout", 3, 91, "9600 bit/s 8E2 (4.38 ms)", "at least 5ms");
    CHECK(diagnostics_of(R"(
gateway: {id: t}
lines:
  - {name: a, port: /dev/ttyS0, baud: 9600, response_timeout: 4ms}
)")
              .empty());

    const char* ranges = R"(
gateway: {id: t}
lines:
  - name: a
    port: /dev/ttyS0
    response_timeout: 11s
    byte_timeout: 0ms
    turnaround: 2s
    read_retries: 6
    offline_after: 0
    offline_backoff: {initial: 10s, max: 5s}
  - name: b
    port: /dev/ttyS1
    offline_backoff: {max: 500ms}
    broadcast_unit: 0
    broadcast_share: 0
)";
    CHECK_REPORTS(ranges, "lines[0].response_timeout", 5, 23, "expected 1ms..10s");
    CHECK_REPORTS(ranges, "lines[0].byte_timeout", 6, 19, "expected 1ms..1s");
    CHECK_REPORTS(ranges, "lines[0].turnaround", 7, 17, "expected 0ms..1s");
    CHECK_REPORTS(ranges, "lines[0].read_retries", 8, 19, "expected 0..5");
    CHECK_REPORTS(ranges, "lines[0].offline_after", 9, 20, "expected 1..100");
    CHECK_REPORTS(ranges, "lines[0].offline_backoff.max", 10, 42, "max (5s) is shorter than initial (10s)");
    CHECK_REPORTS(ranges, "lines[1].offline_backoff.max", 13, 28, "initial (1s, the default)");
    CHECK_REPORTS(ranges, "lines[1].broadcast_unit", 14, 21, "expected 1..247");
    CHECK_REPORTS(ranges, "lines[1].broadcast_share", 15, 22, "expected 1..100");
    CHECK(diagnostics_of(ranges).size() == 9);
}

TEST_CASE("unique unit IDs, names, ports, addresses and servers") {
    const char* yaml = R"(
gateway: {id: t}
lines:
  - name: a
    port: /dev/ttyS0
    broadcast_unit: 5
    devices:
      - {name: d1, type: hiwin-xeg, address: 1, unit_id: 5}
      - {name: d2, type: hiwin-xeg, address: 1, unit_id: 6}
  - name: a
    port: /dev/./ttyS0
    devices:
      - {name: d1, type: hiwin-xeg, address: 1, unit_id: 6}
upstreams:
  - {name: r6, host: r6, units: [{unit_id: 5, name: d2}]}
  - {name: r6, host: r6, port: 502, units: [{unit_id: 7, name: r7}]}
)";
    CHECK_REPORTS(yaml, "lines[0].devices[0].unit_id", 7, 58, "unit 5 is already used by lines[0].broadcast_unit (line 5)",
                  "each unit ID once across devices, broadcast units and upstream units");
    CHECK_REPORTS(yaml, "lines[0].devices[1].address", 8, 46, "address 1 is already used by lines[0].devices[0] (d1)");
    CHECK_REPORTS(yaml, "lines[1].name", 9, 11, "line name 'a' is already used by lines[0].name");
    CHECK_REPORTS(yaml, "lines[1].port", 10, 11, "port /dev/./ttyS0 is already used by lines[0].port (line 4)",
                  "one line per serial port");
    CHECK_REPORTS(yaml, "lines[1].devices[0].name", 12, 16, "device name 'd1' is already used by lines[0].devices[0].name");
    CHECK_REPORTS(yaml, "lines[1].devices[0].unit_id", 12, 58, "unit 6 is already used by lines[0].devices[1].unit_id");
    CHECK_REPORTS(yaml, "upstreams[0].units[0].unit_id", 14, 44, "unit 5 is already used");
    CHECK_REPORTS(yaml, "upstreams[0].units[0].name", 14, 53, "device name 'd2' is already used");
    CHECK_REPORTS(yaml, "upstreams[1].name", 15, 12, "upstream name 'r6' is already used");
    CHECK_REPORTS(yaml, "upstreams[1].host", 15, 22, "server r6:502 is already used", "one connection");
    CHECK(diagnostics_of(yaml).size() == 10);
}

TEST_CASE("two lines on one port through a symbolic link") {
    const auto dir = std::filesystem::temp_directory_path() /
                     ("fb-config-port-" + std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "ttyUSB0") << "";
    std::filesystem::create_symlink(dir / "ttyUSB0", dir / "usb-FTDI-port0");
    const std::string yaml = "gateway: {id: t}\nlines:\n  - {name: a, port: " + (dir / "ttyUSB0").string() +
                             "}\n  - {name: b, port: " + (dir / "usb-FTDI-port0").string() + "}\n";
    const auto diagnostics = diagnostics_of(yaml);
    std::filesystem::remove_all(dir);
    INFO(dump(diagnostics));
    REQUIRE(diagnostics.size() == 1);
    CHECK(diagnostics[0].key == "lines[1].port");
    CHECK(diagnostics[0].line == 4);
    CHECK(diagnostics[0].message.find("already used by lines[0].port") != std::string::npos);
}

TEST_CASE("extreme integers are range errors, never arithmetic overflows") {
    const std::string yaml = one_device("modbus", "9223372036854775807",
                                        "        blocks:\n"
                                        "          - {address: 9223372036854775807, count: 9223372036854775807}\n"
                                        "          - {table: holding, address: 0, count: 9223372036854775807}\n"
                                        "          - {table: holding, address: 0, count: 10}\n",
                                        "-9223372036854775807");
    const auto diagnostics = diagnostics_of(yaml);
    INFO(dump(diagnostics));
    CHECK(find_diagnostic(diagnostics, "lines[0].devices[0].address").has_value());
    CHECK(find_diagnostic(diagnostics, "lines[0].devices[0].unit_id").has_value());
    CHECK(find_diagnostic(diagnostics, "lines[0].devices[0].blocks[0].address").has_value());
    CHECK(find_diagnostic(diagnostics, "lines[0].devices[0].blocks[0].count").has_value());
    CHECK(find_diagnostic(diagnostics, "lines[0].devices[0].blocks[1].count").has_value());
    CHECK_FALSE(find_diagnostic(diagnostics, "lines[0].devices[0].blocks[2]").has_value());
}
