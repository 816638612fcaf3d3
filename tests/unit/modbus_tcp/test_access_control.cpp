// Request scope and rule decisions (pure), and the unit routing table.
#include <vector>
#include <doctest/doctest.h>

#include "fake_targets.hpp"
#include "northbound/modbus_tcp/access_control.hpp"
#include "northbound/modbus_tcp/unit_router.hpp"
#include "test_support.hpp"

namespace fieldbridge::northbound::modbus_tcp {
namespace {

using config::RegisterRange;
using core::FunctionCode;
using core::UnitId;
using protocol::Bytes;

[[nodiscard]] config::IpAddress ip(const char* text) { return *config::parse_ip_address(text); }

TEST_CASE("request_scope reads the address fields of FC01-06, 0F, 10 and both ranges of FC17") {
    CHECK(request_scope(Bytes{0x01, 0x00, 0x10, 0x00, 0x08}) == RequestScope{FunctionCode{0x01}, RegisterRange{0x10, 0x17}, {}});
    CHECK(request_scope(Bytes{0x02, 0x00, 0x00, 0x00, 0x01}) == RequestScope{FunctionCode{0x02}, RegisterRange{0, 0}, {}});
    CHECK(request_scope(Bytes{0x03, 0x01, 0x00, 0x00, 0x7D}) == RequestScope{FunctionCode{0x03}, RegisterRange{0x100, 0x17C}, {}});
    CHECK(request_scope(Bytes{0x04, 0x03, 0x00, 0x00, 0x02}) == RequestScope{FunctionCode{0x04}, RegisterRange{0x300, 0x301}, {}});
    CHECK(request_scope(Bytes{0x05, 0x00, 0x07, 0xFF, 0x00}) == RequestScope{FunctionCode{0x05}, RegisterRange{7, 7}, {}});
    CHECK(request_scope(Bytes{0x06, 0x01, 0x02, 0x00, 0x01}) == RequestScope{FunctionCode{0x06}, RegisterRange{0x102, 0x102}, {}});
    CHECK(request_scope(Bytes{0x0F, 0x00, 0x13, 0x00, 0x0A, 0x02, 0xCD, 0x01}) ==
          RequestScope{FunctionCode{0x0F}, RegisterRange{0x13, 0x1C}, {}});
    CHECK(request_scope(Bytes{0x10, 0x00, 0x01, 0x00, 0x02, 0x04, 0x00, 0x0A, 0x01, 0x02}) ==
          RequestScope{FunctionCode{0x10}, RegisterRange{1, 2}, {}});
    // FC17 (V1.1b3 section 6.17 example): read 3 from 0x0003, write 3 at 0x000E.
    CHECK(request_scope(Bytes{0x17, 0x00, 0x03, 0x00, 0x06, 0x00, 0x0E, 0x00, 0x03, 0x06, 0, 0xFF, 0, 0xFF, 0, 0xFF}) ==
          RequestScope{FunctionCode{0x17}, RegisterRange{3, 8}, RegisterRange{0x0E, 0x10}});
}

TEST_CASE("request_scope fails closed: what it cannot derive touches every register") {
    const RegisterRange all{0x0000, 0xFFFF};
    // Only the function codes that read no register and change nothing have no range.
    for (const std::uint8_t function : std::vector<std::uint8_t>{0x07, 0x0B, 0x0C, 0x11}) {
        CHECK(request_scope(Bytes{function}) == RequestScope{FunctionCode{function}, {}, {}});
    }
    // FC22 (0x16, mask write) is derived: its one register.
    CHECK(request_scope(Bytes{0x16, 0x4E, 0x20, 0xFF, 0xFF, 0x00, 0x01}) ==
          RequestScope{FunctionCode{0x16}, RegisterRange{0x4E20, 0x4E20}, {}});
    // Diagnostics, file records, FIFO, encapsulated transport, vendor codes, 0 and >= 0x80.
    for (const std::uint8_t function : std::vector<std::uint8_t>{0x08, 0x14, 0x15, 0x18, 0x2B, 0x41, 0x64, 0x00, 0x85, 0xFF}) {
        CHECK(request_scope(Bytes{function, 0x0E, 0x01, 0x00}) == RequestScope{FunctionCode{function}, all, {}});
    }
    // Too short to carry the address fields.
    CHECK(request_scope(Bytes{0x03, 0x00, 0x10, 0x00}) == RequestScope{FunctionCode{0x03}, all, {}});
    CHECK(request_scope(Bytes{0x06, 0x00}) == RequestScope{FunctionCode{0x06}, all, {}});
    CHECK(request_scope(Bytes{0x16, 0x4E}) == RequestScope{FunctionCode{0x16}, all, {}});
    CHECK(request_scope(Bytes{0x17, 0x00, 0x03, 0x00, 0x06, 0x00, 0x0E, 0x00}) == RequestScope{FunctionCode{0x17}, all, {}});
    CHECK(request_scope(Bytes{}) == RequestScope{FunctionCode{0x00}, all, {}});
}

TEST_CASE("request_scope: a malformed quantity never shrinks the range") {
    // Quantity 0 still names the addressed register.
    CHECK(request_scope(Bytes{0x03, 0x00, 0x64, 0x00, 0x00}) == RequestScope{FunctionCode{0x03}, RegisterRange{100, 100}, {}});
    // Past 0xFFFF: ends at 0xFFFF.
    CHECK(request_scope(Bytes{0x10, 0xFF, 0xFE, 0x00, 0x7B}) == RequestScope{FunctionCode{0x10}, RegisterRange{0xFFFE, 0xFFFF}, {}});
}

TEST_CASE("request_scope of a decoded request: the same scope as the header bytes, which malformed PDUs keep") {
    // The server decodes each PDU once (RequestPdu); the rules read the typed request.
    const std::vector<Bytes> well_formed{
        Bytes{0x01, 0x00, 0x10, 0x00, 0x08},
        Bytes{0x02, 0x00, 0x00, 0x00, 0x01},
        Bytes{0x03, 0x01, 0x00, 0x00, 0x7D},
        Bytes{0x04, 0x03, 0x00, 0x00, 0x02},
        Bytes{0x05, 0x00, 0x07, 0xFF, 0x00},
        Bytes{0x06, 0x01, 0x02, 0x00, 0x01},
        Bytes{0x07},
        Bytes{0x0F, 0x00, 0x13, 0x00, 0x0A, 0x02, 0xCD, 0x01},
        Bytes{0x10, 0x00, 0x01, 0x00, 0x02, 0x04, 0x00, 0x0A, 0x01, 0x02},
        Bytes{0x16, 0x00, 0x04, 0x00, 0xF2, 0x00, 0x25},
        Bytes{0x17, 0x00, 0x03, 0x00, 0x06, 0x00, 0x0E, 0x00, 0x03, 0x06, 0, 0xFF, 0, 0xFF, 0, 0xFF},
        Bytes{0x11},
        Bytes{0x08, 0x00, 0x00, 0xA5, 0x37},
        Bytes{0x2B, 0x0E, 0x01, 0x00},
    };
    for (const Bytes& pdu : well_formed) {
        CAPTURE(static_cast<int>(pdu[0]));
        const RequestPdu request = RequestPdu::decode(pdu);
        REQUIRE(request.decoded.complete());
        CHECK(request_scope(request) == request_scope(pdu));
    }
    // A write whose byte count does not match: not decoded, the header bytes still name
    // its range (and a deny rule over it still matches).
    const Bytes malformed{0x10, 0x00, 0x20, 0x00, 0x02, 0x03, 0x00, 0x01};
    const RequestPdu request = RequestPdu::decode(malformed);
    CHECK_FALSE(request.decoded.complete());
    CHECK(request_scope(request) == RequestScope{FunctionCode{0x10}, RegisterRange{0x20, 0x21}, {}});
}

TEST_CASE("request_allowed: first matching rule decides, FC17 needs both ranges allowed") {
    config::ModbusTcpConfig config;
    CHECK(request_allowed(config, ip("10.0.0.1"), UnitId{1}, request_scope(Bytes{0x06, 0, 1, 0, 1})));  // no rules

    config::AccessRule plc_writes;  // the PLC may write registers 0x100-0x1FF of unit 1
    plc_writes.clients = {test::cidr("10.0.0.5")};
    plc_writes.units = {UnitId{1}};
    plc_writes.functions = {FunctionCode{0x06}, FunctionCode{0x10}, FunctionCode{0x17}};
    plc_writes.registers = RegisterRange{0x100, 0x1FF};
    plc_writes.action = config::RuleAction::allow;
    config::AccessRule no_other_writes;
    no_other_writes.functions = {FunctionCode{0x05}, FunctionCode{0x06}, FunctionCode{0x0F}, FunctionCode{0x10},
                                 FunctionCode{0x17}};
    no_other_writes.action = config::RuleAction::deny;
    config.rules = {plc_writes, no_other_writes};

    const auto plc = ip("10.0.0.5");
    const auto scada = ip("10.0.0.9");
    CHECK(request_allowed(config, plc, UnitId{1}, request_scope(Bytes{0x06, 0x01, 0x10, 0, 1})));
    CHECK_FALSE(request_allowed(config, plc, UnitId{2}, request_scope(Bytes{0x06, 0x01, 0x10, 0, 1})));   // other unit
    CHECK_FALSE(request_allowed(config, plc, UnitId{1}, request_scope(Bytes{0x06, 0x00, 0x10, 0, 1})));   // outside
    CHECK_FALSE(request_allowed(config, scada, UnitId{1}, request_scope(Bytes{0x06, 0x01, 0x10, 0, 1})));  // not the PLC
    CHECK(request_allowed(config, scada, UnitId{1}, request_scope(Bytes{0x03, 0x01, 0x10, 0, 1})));        // reads pass
    // Allow needs containment: a write reaching past 0x1FF is denied.
    CHECK_FALSE(request_allowed(config, plc, UnitId{1}, request_scope(Bytes{0x10, 0x01, 0xFF, 0, 2, 4, 0, 1, 0, 2})));
    // FC17 of the PLC: the read range outside its allow rule falls to the deny rule.
    const Bytes rw_inside{0x17, 0x01, 0x00, 0x00, 0x01, 0x01, 0x10, 0x00, 0x01, 0x02, 0x00, 0x01};
    const Bytes rw_read_outside{0x17, 0x00, 0x00, 0x00, 0x01, 0x01, 0x10, 0x00, 0x01, 0x02, 0x00, 0x01};
    CHECK(request_allowed(config, plc, UnitId{1}, request_scope(rw_inside)));
    CHECK_FALSE(request_allowed(config, plc, UnitId{1}, request_scope(rw_read_outside)));
    // A truncated write may touch anything: the allow rule (with a range) cannot match it.
    CHECK_FALSE(request_allowed(config, plc, UnitId{1}, request_scope(Bytes{0x06, 0x01})));
}

TEST_CASE("a deny rule matches any overlap with its register range") {
    config::ModbusTcpConfig config;
    config::AccessRule protect;
    protect.registers = RegisterRange{0x0200, 0x0203};
    protect.action = config::RuleAction::deny;
    config.rules = {protect};
    const auto client = ip("192.168.1.2");
    CHECK_FALSE(request_allowed(config, client, UnitId{7}, request_scope(Bytes{0x03, 0x01, 0xF0, 0x00, 0x20})));
    CHECK(request_allowed(config, client, UnitId{7}, request_scope(Bytes{0x03, 0x01, 0xF0, 0x00, 0x10})));  // ends at 0x1FF
    CHECK(request_allowed(config, client, UnitId{7}, request_scope(Bytes{0x07})));  // no registers: no match
    // Fail closed: FC22 in the range, and what the server cannot derive, are denied.
    CHECK_FALSE(request_allowed(config, client, UnitId{7}, request_scope(Bytes{0x16, 0x02, 0x01, 0xFF, 0xFF, 0, 1})));
    CHECK(request_allowed(config, client, UnitId{7}, request_scope(Bytes{0x16, 0x02, 0x04, 0xFF, 0xFF, 0, 1})));
    CHECK_FALSE(request_allowed(config, client, UnitId{7}, request_scope(Bytes{0x15, 0x07, 0x06, 0, 1, 0, 0, 0, 1})));
    CHECK_FALSE(request_allowed(config, client, UnitId{7}, request_scope(Bytes{0x41, 0x00})));
}

TEST_CASE("UnitRouter: set, replace, remove, distinct targets") {
    asio::io_context io;
    test::ImmediateTarget a(io);
    test::ImmediateTarget b(io);
    UnitRouter router;
    CHECK(router.find(UnitId{1}) == nullptr);
    router.set(UnitId{1}, a);
    router.set(UnitId{2}, a);
    router.set(UnitId{200}, b);
    CHECK(router.find(UnitId{1}) == &a);
    CHECK(router.find(UnitId{200}) == &b);
    CHECK(router.size() == 3);
    CHECK(router.targets() == std::vector<UnitTarget*>{&a, &b});
    router.set(UnitId{2}, b);
    CHECK(router.find(UnitId{2}) == &b);
    router.remove(UnitId{1});
    CHECK(router.find(UnitId{1}) == nullptr);
    CHECK(router.targets() == std::vector<UnitTarget*>{&b});
    router.clear();
    CHECK(router.size() == 0);
    CHECK(router.targets().empty());
}

}  // namespace
}  // namespace fieldbridge::northbound::modbus_tcp
