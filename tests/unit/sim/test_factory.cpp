// make_device(): the type names, options and errors the simulator runtime relies on.
#include <doctest/doctest.h>

#include <stdexcept>

#include "models/device_factory.hpp"
#include "sim_test_support.hpp"

namespace fieldbridge::test {

TEST_CASE("factory: every type name builds its device") {
    const sim::DeviceOptions options;
    for (const auto type : sim::device_types()) {
        INFO(type);
        const auto device = sim::make_device(type, 3, options);
        REQUIRE(device != nullptr);
        CHECK(device->type() == type);
        CHECK(device->address() == 3);
        CHECK(device->protocol() == (type == "wtec-ascii" ? sim::BusProtocol::wtec_ascii
                                                          : sim::BusProtocol::modbus_rtu));
    }
    CHECK(sim::device_types().size() == 5);
}

TEST_CASE("factory: options reach the models") {
    SimClock clock;
    sim::DeviceOptions options;
    options.xeg_model = 0x0A40;
    const auto xeg = sim::make_device("hiwin-xeg", 2, options);
    CHECK(exchange(*xeg, rtu("02 03 06 00 00 01"), clock.now()) == hex_of(rtu("02 03 02 0A 40")));

    options.excd_word_order = "low_first";
    const auto excd = sim::make_device("excd203mb", 1, options);
    REQUIRE(exchange(*excd, rtu("01 10 00 14 00 02 04 35 00 00 0C"), clock.now()) ==
            hex_of(rtu("01 10 00 14 00 02")));
    CHECK(exchange(*excd, rtu("01 03 00 14 00 02"), clock.now()) == hex_of(rtu("01 03 04 35 00 00 0C")));

    options.wtec_stroke = 1000;
    const auto wtec = sim::make_device("wtec-rtu", 1, options);
    REQUIRE(exchange(*wtec, rtu("01 06 01 00 00 01"), clock.now()) == hex_of(rtu("01 06 01 00 00 01")));
    clock.advance_s(1);
    REQUIRE(exchange(*wtec, rtu("01 06 01 05 00 19"), clock.now()) == hex_of(rtu("01 06 01 05 00 19")));
    clock.advance_s(1);
    CHECK(exchange(*wtec, rtu("01 03 02 04 00 01"), clock.now()) == hex_of(rtu("01 03 02 00 19")));
}

TEST_CASE("factory: errors say what is wrong") {
    const sim::DeviceOptions options;
    CHECK_THROWS_AS((void)sim::make_device("hiwin", 1, options), std::invalid_argument);
    CHECK_THROWS_AS((void)sim::make_device("hiwin-xeg", 0, options), std::invalid_argument);
    CHECK_THROWS_AS((void)sim::make_device("excd203mb", 255, options), std::invalid_argument);
    sim::DeviceOptions bad = options;
    bad.excd_word_order = "middle";
    CHECK_THROWS_AS((void)sim::make_device("excd203mb", 1, bad), std::invalid_argument);
    bad = options;
    bad.xeg_model = 0x0A11;
    CHECK_THROWS_AS((void)sim::make_device("hiwin-xeg", 1, bad), std::invalid_argument);
    bad = options;
    bad.wtec_stroke = 0;
    CHECK_THROWS_AS((void)sim::make_device("wtec-ascii", 1, bad), std::invalid_argument);
    try {
        (void)sim::make_device("wtec", 1, options);
        FAIL("no exception");
    } catch (const std::invalid_argument& e) {
        const std::string text = e.what();
        CHECK(text.find("\"wtec\"") != std::string::npos);
        CHECK(text.find("wtec-rtu") != std::string::npos);
    }
}

}  // namespace fieldbridge::test
