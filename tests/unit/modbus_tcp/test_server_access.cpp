// Access rules end to end: a denied request gets exception 0x01 and never reaches
// its target.
#include <doctest/doctest.h>

#include "fake_targets.hpp"
#include "protocol/modbus_pdu.hpp"
#include "test_support.hpp"

namespace fieldbridge::northbound::modbus_tcp::test {
namespace {

/// Loopback clients may read anything, write unit 1 only outside 100-199, and
/// unit 2 is read-only for registers 0-9.
[[nodiscard]] config::ModbusTcpConfig ruled_config() {
    auto config = loopback_config();
    config::AccessRule protect;
    protect.clients = {cidr("127.0.0.0/8")};
    protect.units = {core::UnitId{1}};
    protect.functions = {core::FunctionCode{0x06}, core::FunctionCode{0x10}, core::FunctionCode{0x17}};
    protect.registers = config::RegisterRange{100, 199};
    protect.action = config::RuleAction::deny;
    config::AccessRule window;
    window.units = {core::UnitId{2}};
    window.functions = {core::FunctionCode{0x03}};
    window.registers = config::RegisterRange{0, 9};
    window.action = config::RuleAction::allow;
    config::AccessRule rest_of_unit2;
    rest_of_unit2.units = {core::UnitId{2}};
    rest_of_unit2.action = config::RuleAction::deny;
    config.rules = {protect, window, rest_of_unit2};
    return config;
}

TEST_CASE("access rules: denied requests get exception 0x01 and the target never sees them") {
    Harness h(ruled_config(), {}, [](Harness& self) {
        self.add_target<ImmediateTarget>({1});
        self.add_target<ImmediateTarget>({2});
    });
    Client client(h.port);
    const auto seen = [&](std::size_t index) {
        return h.on_loop([&] { return dynamic_cast<ImmediateTarget&>(*h.targets.at(index)).seen.size(); });
    };

    auto response = client.ask(write_register(1, 1, 150, 7));
    REQUIRE(response);
    CHECK(response->transaction_id == 1);
    CHECK(response->unit_id == core::UnitId{1});
    CHECK(response->pdu == exception_pdu(0x06, 0x01));
    CHECK(seen(0) == 0);

    response = client.ask(write_register(2, 1, 50, 7));  // outside the protected range
    REQUIRE(response);
    CHECK(response->pdu == Bytes{0x06, 0x00, 0x32, 0x00, 0x07});
    CHECK(seen(0) == 1);

    response = client.ask(read_registers(3, 1, 150, 1));  // reads are not ruled
    REQUIRE(response);
    CHECK(response->pdu[0] == 0x03);

    response = client.ask(read_write_registers(4, 1, 0, 1, 120, 5));  // FC17 writing a protected register
    REQUIRE(response);
    CHECK(response->pdu == exception_pdu(0x17, 0x01));
    CHECK(seen(0) == 2);

    response = client.ask(read_registers(5, 2, 0, 10));  // inside the allowed window
    REQUIRE(response);
    CHECK(response->pdu[0] == 0x03);
    response = client.ask(read_registers(6, 2, 5, 10));  // reaches past it
    REQUIRE(response);
    CHECK(response->pdu == exception_pdu(0x03, 0x01));
    response = client.ask(read_registers(7, 2, 0, 1, 0x04));  // another function
    REQUIRE(response);
    CHECK(response->pdu == exception_pdu(0x04, 0x01));
    response = client.ask(protocol::encode_mbap(8, core::UnitId{2}, Bytes{0x07}));  // FC07: no registers, denied by rule 3
    REQUIRE(response);
    CHECK(response->pdu == exception_pdu(0x07, 0x01));
    CHECK(seen(1) == 1);

    const auto stats = h.stats();
    CHECK(stats.denied == 5);
    CHECK(stats.exceptions(0x01) == 5);
    CHECK(stats.requests == 8);
    CHECK(stats.connections_open == 1);  // a denial does not close the connection
}

TEST_CASE("a reload changes the rules for open connections") {
    Harness h(loopback_config(), {}, [](Harness& self) { self.add_target<ImmediateTarget>({1}); });
    Client client(h.port);
    REQUIRE(client.ask(write_register(1, 1, 150, 7))->pdu[0] == 0x06);
    h.on_loop([&] {
        h.server->apply(std::make_shared<const config::ModbusTcpConfig>(ruled_config()));
        return 0;
    });
    const auto response = client.ask(write_register(2, 1, 150, 7));
    REQUIRE(response);
    CHECK(response->pdu == exception_pdu(0x06, 0x01));
}

}  // namespace
}  // namespace fieldbridge::northbound::modbus_tcp::test
