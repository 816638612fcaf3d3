// Access control decisions of the Modbus TCP section: allow-list, then the first
// matching rule; no match allows.

#include <doctest/doctest.h>

#include "config_test_support.hpp"

using namespace fieldbridge::config;
using namespace fieldbridge::config::test;
using fieldbridge::core::FunctionCode;
using fieldbridge::core::UnitId;

namespace {

IpAddress ip(const char* text) {
    const auto address = parse_ip_address(text);
    REQUIRE(address.has_value());
    return *address;
}

constexpr FunctionCode fc03{3};
constexpr FunctionCode fc07{7};
constexpr FunctionCode fc16{16};

}  // namespace

TEST_CASE("allow-list and rules") {
    const auto config = load_ok(R"(
gateway: {id: t}
lines:
  - name: a
    port: /dev/ttyS0
    devices:
      - {name: g, type: hiwin-xeg, address: 1, unit_id: 1}
      - {name: s, type: excd203mb, address: 2, unit_id: 2}
modbus_tcp:
  allow: [10.0.0.0/8, "fd00::/8"]
  rules:
    - {clients: [10.1.0.0/16], functions: [5, 6, 15, 16], action: deny}
    - {clients: [10.2.0.10], units: [1], functions: [16], registers: {from: 0x0600, to: 0x0646}, action: allow}
    - {units: [1], registers: {from: 0x0600, to: 0x0646}, action: deny}
)");
    REQUIRE(config);
    const auto& tcp = config->modbus_tcp;

    CHECK(tcp.client_allowed(ip("10.5.5.5")));
    CHECK(tcp.client_allowed(ip("::ffff:10.1.1.1")));  // IPv4 client on a dual-stack socket
    CHECK(tcp.client_allowed(ip("fd00::1")));
    CHECK_FALSE(tcp.client_allowed(ip("192.168.1.1")));
    CHECK_FALSE(tcp.client_allowed(ip("::1")));

    const RegisterRange move{0x0630, 0x0632};
    // SCADA network: no writes at all, reads pass.
    CHECK(tcp.decide(ip("10.1.2.3"), UnitId{1}, fc16, move) == RuleAction::deny);
    CHECK(tcp.decide(ip("10.1.2.3"), UnitId{2}, fc16, RegisterRange{0x0100, 0x0101}) == RuleAction::deny);
    CHECK(tcp.decide(ip("10.1.2.3"), UnitId{1}, fc03, RegisterRange{0x0300, 0x0301}) == RuleAction::allow);
    // The PLC may write the motion registers of unit 1...
    CHECK(tcp.decide(ip("10.2.0.10"), UnitId{1}, fc16, move) == RuleAction::allow);
    // ...but an allow rule covers only requests entirely inside its range; the deny
    // rule then matches a request that touches the range.
    CHECK(tcp.decide(ip("10.2.0.10"), UnitId{1}, fc16, RegisterRange{0x0640, 0x0650}) == RuleAction::deny);
    // Nobody else writes them.
    CHECK(tcp.decide(ip("10.3.0.1"), UnitId{1}, fc16, move) == RuleAction::deny);
    CHECK(tcp.decide(ip("10.3.0.1"), UnitId{1}, fc03, RegisterRange{0x0646, 0x0647}) == RuleAction::deny);
    // Other units and other registers are not concerned.
    CHECK(tcp.decide(ip("10.3.0.1"), UnitId{2}, fc16, move) == RuleAction::allow);
    CHECK(tcp.decide(ip("10.3.0.1"), UnitId{1}, fc16, RegisterRange{0x0647, 0x0650}) == RuleAction::allow);
    // A request without registers (FC07) never matches a rule with a register range.
    CHECK(tcp.decide(ip("10.3.0.1"), UnitId{1}, fc07, std::nullopt) == RuleAction::allow);
}

TEST_CASE("no allow-list and no rules: everything is allowed") {
    const auto config = load_ok("gateway: {id: t}\nmodbus_tcp: {allow: [], rules: []}\n");
    REQUIRE(config);
    CHECK(config->modbus_tcp.client_allowed(ip("203.0.113.9")));
    CHECK(config->modbus_tcp.decide(ip("203.0.113.9"), UnitId{7}, fc16, RegisterRange{0, 10}) == RuleAction::allow);
}
