// make_profile: one profile per device type, options checked.
#include <doctest/doctest.h>

#include <chrono>
#include <string>

#include "engine/profiles/profile_factory.hpp"
#include "support.hpp"

using namespace fbt;

TEST_CASE("factory: every type, with its name, bus and broadcast address") {
    fe::ProfileOptions o;
    o.wtec_stroke = 1000;
    o.blocks = {{fe::Table::holding, 0, 1, std::chrono::milliseconds{100}, false}};
    struct Expect {
        fe::DeviceType type;
        const char* name;
        fe::Bus bus;
        std::uint8_t broadcast;
    };
    for (const Expect& e : {Expect{fe::DeviceType::hiwin_xeg, "hiwin-xeg", fe::Bus::modbus_rtu, 0},
                            Expect{fe::DeviceType::excd203mb, "excd203mb", fe::Bus::modbus_rtu, 0xFF},
                            Expect{fe::DeviceType::wtec_rtu, "wtec-rtu", fe::Bus::modbus_rtu, 0},
                            Expect{fe::DeviceType::wtec_ascii, "wtec-ascii", fe::Bus::wtec_ascii, 0},
                            Expect{fe::DeviceType::modbus, "modbus", fe::Bus::modbus_rtu, 0}}) {
        const auto p = fe::make_profile(e.type, o);
        CHECK(p->type() == e.type);
        CHECK(fe::to_string(p->type()) == e.name);
        CHECK(p->bus() == e.bus);
        CHECK(p->broadcast_address() == fieldbridge::core::BusAddress{e.broadcast});
        const fe::PollPlan plan = p->poll_plan();
        CHECK_FALSE(plan.items().empty());
    }
}

TEST_CASE("factory: a wtec-ascii device without a stroke is refused, naming the option") {
    try {
        (void)fe::make_profile(fe::DeviceType::wtec_ascii, fe::ProfileOptions{});
        FAIL("no ProfileError");
    } catch (const fe::ProfileError& e) {
        CHECK(std::string{e.what()}.find("`stroke`") != std::string::npos);
    }
    CHECK_THROWS_AS((void)fe::make_profile(fe::DeviceType::modbus, fe::ProfileOptions{}), fe::ProfileError);
}
