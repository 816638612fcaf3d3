// Huacheng R6: motion over simulated time, commands, coils and the exception rules.
#include <doctest/doctest.h>

#include "models/r6_model.hpp"
#include "sim_test_support.hpp"

namespace fieldbridge::test {
namespace {

std::string ask_pdu(sim::R6Model& r6, std::string_view pdu_hex, Clock::time_point now) {
    return hex_of(r6.handle_pdu(hex(pdu_hex), now));
}

}  // namespace

TEST_CASE("r6: start moves the axes; cycles update the times and counter 0") {
    SimClock clock;
    sim::R6Model r6;
    CHECK(ask_pdu(r6, "06 4e 23 00 01", clock.now()) == "06 4E 23 00 01");  // start button
    CHECK(ask_pdu(r6, "03 08 89 00 01", clock.now()) == "03 02 00 02");     // auto
    clock.advance_s(1);
    // Axis 0 at 10 deg/s, axis 1 scaled to its 40 deg sweep.
    CHECK(ask_pdu(r6, "03 08 dc 00 04", clock.now()) == hex_of(hex("03 08 00 00 27 10 00 00 34 15")));
    CHECK(ask_pdu(r6, "03 09 1c 00 02", clock.now()) == hex_of(hex("03 04 00 00 27 10")));
    CHECK(ask_pdu(r6, "03 09 5d 00 04", clock.now()) == hex_of(hex("03 08 00 00 00 00 00 00 03 E8")));
    CHECK(ask_pdu(r6, "03 09 66 00 02", clock.now()) == hex_of(hex("03 04 03 06 03 1A")));  // 774, 794
    CHECK(ask_pdu(r6, "03 09 86 00 01", clock.now()) == hex_of(hex("03 02 00 53")));        // 83 rpm
    // Axis 0 sweeps 0 -> 30 -> 0 degrees: one cycle is 6 s.
    clock.advance_s(3);
    CHECK(r6.axis_position(0) == 10000);  // the model moves only when asked or advanced
    (void)ask_pdu(r6, "03 00 00 00 01", clock.now());
    CHECK(r6.axis_position(0) == 20000);
    clock.advance_s(2);
    CHECK(ask_pdu(r6, "03 09 61 00 04", clock.now()) == hex_of(hex("03 08 00 00 00 00 00 00 17 70")));
    CHECK(ask_pdu(r6, "03 09 5d 00 04", clock.now()) == hex_of(hex("03 08 00 00 00 00 00 00 00 00")));
    CHECK(ask_pdu(r6, "10 08 83 00 02 04 00 00 00 00", clock.now()) == "10 08 83 00 02");
    CHECK(ask_pdu(r6, "03 08 87 00 02", clock.now()) == hex_of(hex("03 04 00 00 00 01")));
    // Half the global speed: 5 deg/s.
    CHECK(ask_pdu(r6, "06 4e e8 01 f4", clock.now()) == "06 4E E8 01 F4");
    clock.advance_s(2);
    CHECK(r6.axis_position(0) == 0);
    (void)ask_pdu(r6, "03 00 00 00 01", clock.now());
    CHECK(r6.axis_position(0) == 10000);
    // Single cycle: stops at the end of this cycle (10 s more at 5 deg/s).
    CHECK(ask_pdu(r6, "06 4e 22 00 00", clock.now()) == "06 4E 22 00 00");
    clock.advance_s(9);
    CHECK(ask_pdu(r6, "03 09 a6 00 01", clock.now()) == "03 02 00 01");
    clock.advance_s(2);
    CHECK(ask_pdu(r6, "03 09 a6 00 01", clock.now()) == "03 02 00 00");
    CHECK(ask_pdu(r6, "03 09 61 00 04", clock.now()) == hex_of(hex("03 08 00 00 00 00 00 00 2E E0")));  // 12 s
    CHECK(ask_pdu(r6, "03 09 86 00 01", clock.now()) == "03 02 00 00");
}

TEST_CASE("r6: pause, stop, alarms and clearing") {
    SimClock clock;
    sim::R6Model r6;
    REQUIRE(r6.control("start", clock.now()).empty());
    clock.advance_s(1);
    CHECK(ask_pdu(r6, "06 4e 21 00 00", clock.now()) == "06 4E 21 00 00");  // pause
    clock.advance_s(5);
    CHECK(ask_pdu(r6, "03 08 dc 00 02", clock.now()) == hex_of(hex("03 04 00 00 27 10")));
    CHECK(ask_pdu(r6, "03 09 a6 00 01", clock.now()) == "03 02 00 00");
    // An alarm stops the robot; start is refused until it is cleared.
    REQUIRE(r6.control("start", clock.now()).empty());
    REQUIRE(r6.control("alarm 805", clock.now()).empty());
    CHECK(!r6.moving());
    CHECK(ask_pdu(r6, "06 4e 23 00 01", clock.now()) == "06 4E 23 00 01");
    CHECK(!r6.moving());
    CHECK(!r6.control("start", clock.now()).empty());
    CHECK(ask_pdu(r6, "06 4e 26 00 01", clock.now()) == "06 4E 26 00 01");  // clear alarm, continue
    CHECK(r6.alarm() == 0);
    CHECK(r6.moving());
    REQUIRE(r6.control("alarm 12", clock.now()).empty());
    CHECK(ask_pdu(r6, "06 4e 25 00 01", clock.now()) == "06 4E 25 00 01");
    CHECK(r6.moving());
    CHECK(ask_pdu(r6, "06 4e 24 00 01", clock.now()) == "06 4E 24 00 01");  // stop button
    CHECK(!r6.moving());
    // Without origins there is no start either.
    REQUIRE(r6.control("origin 0", clock.now()).empty());
    CHECK(ask_pdu(r6, "03 09 a7 00 01", clock.now()) == "03 02 00 00");
    CHECK(ask_pdu(r6, "06 4e 23 00 01", clock.now()) == "06 4E 23 00 01");
    CHECK(!r6.moving());
}

TEST_CASE("r6: coils are the outputs of the boards") {
    SimClock clock;
    sim::R6Model r6;
    CHECK(ask_pdu(r6, "05 00 01 FF 00", clock.now()) == "05 00 01 FF 00");
    CHECK(ask_pdu(r6, "03 08 b3 00 02", clock.now()) == hex_of(hex("03 04 00 00 00 02")));
    CHECK(ask_pdu(r6, "01 00 00 00 08", clock.now()) == "01 01 02");
    CHECK(ask_pdu(r6, "05 01 1F FF 00", clock.now()) == "05 01 1F FF 00");  // EUY047: EU board bit 31
    CHECK(ask_pdu(r6, "03 08 c3 00 02", clock.now()) == hex_of(hex("03 04 80 00 00 00")));
    CHECK(ask_pdu(r6, "05 00 01 00 00", clock.now()) == "05 00 01 00 00");
    CHECK(ask_pdu(r6, "01 00 00 00 08", clock.now()) == "01 01 00");
    CHECK(ask_pdu(r6, "05 01 20 FF 00", clock.now()) == "85 02");
    CHECK(ask_pdu(r6, "01 01 10 00 11", clock.now()) == "81 02");
    CHECK(ask_pdu(r6, "05 00 01 12 34", clock.now()) == "85 03");
}

TEST_CASE("r6: exception rules") {
    SimClock clock;
    sim::R6Model r6;
    const auto now = clock.now();
    SUBCASE("02: not the start of a value, half a value, unknown, missing axis or board") {
        CHECK(ask_pdu(r6, "03 08 84 00 01", now) == "83 02");
        CHECK(ask_pdu(r6, "03 08 83 00 01", now) == "83 02");
        CHECK(ask_pdu(r6, "03 00 83 00 03", now) == "83 02");
        CHECK(ask_pdu(r6, "03 08 e8 00 02", now) == "83 02");  // axis 6 of 6
        CHECK(ask_pdu(r6, "03 09 5e 00 01", now) == "83 02");
        CHECK(ask_pdu(r6, "03 09 5d 00 02", now) == "83 02");
        CHECK(ask_pdu(r6, "03 00 41 00 01", now) == "83 02");  // mold number: not on the host
        CHECK(ask_pdu(r6, "03 4e 20 00 01", now) == "83 02");  // commands are write-only
        CHECK(ask_pdu(r6, "03 08 b5 00 02", now) == "83 02");  // IO board 1 of 1
        CHECK(ask_pdu(r6, "10 4e 20 00 01 02 00 01", now) == "90 02");
        CHECK(ask_pdu(r6, "10 08 83 00 01 02 00 01", now) == "90 02");
        CHECK(ask_pdu(r6, "10 08 85 00 02 04 00 00 00 01", now) == "90 02");
        CHECK(ask_pdu(r6, "06 08 83 00 01", now) == "86 02");
        CHECK(ask_pdu(r6, "06 4f 4c 00 01", now) == "86 02");
        CHECK(ask_pdu(r6, "10 75 37 00 02 04 00 00 00 01", now) == "90 02");
    }
    SUBCASE("03: values") {
        CHECK(ask_pdu(r6, "06 4e e8 03 e9", now) == "86 03");
        CHECK(ask_pdu(r6, "10 08 83 00 02 04 00 00 00 07", now) == "90 03");
        CHECK(ask_pdu(r6, "10 4e 52 00 06 0c 00 00 00 09 00 00 00 00 00 00 00 08", now) == "90 03");
        CHECK(ask_pdu(r6, "10 4e 58 00 03 06 00 01 00 01 00 01", now) == "90 03");  // board 1 of 1
        CHECK(ask_pdu(r6, "10 4e 58 00 03 06 00 00 00 20 00 01", now) == "90 03");
        CHECK(ask_pdu(r6, "10 4e 58 00 03 06 00 00 00 01 00 02", now) == "90 03");
        CHECK(ask_pdu(r6, "06 75 33 00 05", now) == "86 03");
        CHECK(ask_pdu(r6, "10 75 35 00 04 08 00 01 00 01 00 00 00 01", now) == "90 03");
        CHECK(ask_pdu(r6, "03 00 00 00 00", now) == "83 03");
    }
    SUBCASE("01: function codes the R6 does not serve") {
        CHECK(ask_pdu(r6, "02 00 00 00 01", now) == "82 01");
        CHECK(ask_pdu(r6, "0f 00 00 00 01 01 01", now) == "8F 01");
        CHECK(ask_pdu(r6, "17 00 00 00 01 00 00 00 01 02 00 00", now) == "97 01");
    }
    SUBCASE("FC04 reads the same map; M and EU boards always exist") {
        CHECK(ask_pdu(r6, "04 00 00 00 01", now) == "04 02 00 29");
        CHECK(ask_pdu(r6, "03 08 95 00 02", now) == hex_of(hex("03 04 00 00 00 00")));
        CHECK(ask_pdu(r6, "10 4e 58 00 03 06 00 05 00 1F 00 01", now) == "10 4E 58 00 03");  // M board 0
        CHECK(ask_pdu(r6, "03 08 bd 00 02", now) == hex_of(hex("03 04 80 00 00 00")));
    }
    SUBCASE("data source: clear and view") {
        CHECK(ask_pdu(r6, "10 75 35 00 0E 1C 00 01 00 01 00 00 00 01 00 00 00 02 00 00 00 03 00 00 00 04 00 00 00 05 00 00 00 06",
                  now) == "10 75 35 00 0E");
        CHECK(ask_pdu(r6, "10 75 35 00 0E 1C 00 01 00 00 00 00 00 01 00 00 00 02 00 00 00 03 00 00 00 04 00 00 00 05 00 00 00 06",
                  now) == "10 75 35 00 0E");
        CHECK(ask_pdu(r6, "03 75 31 00 01", now) == "03 02 00 02");
        CHECK(ask_pdu(r6, "06 75 36 00 01", now) == "06 75 36 00 01");
        CHECK(ask_pdu(r6, "03 75 31 00 01", now) == "03 02 00 00");
        CHECK(ask_pdu(r6, "06 75 30 00 07", now) == "06 75 30 00 07");
        CHECK(ask_pdu(r6, "03 75 30 00 02", now) == "03 04 00 07 00 00");
    }
    SUBCASE("control errors") {
        CHECK(!r6.control("alarm x", now).empty());
        CHECK(!r6.control("io_boards 6", now).empty());
        CHECK(!r6.control("axes 9", now).empty());
        CHECK(!r6.control("input 9 1", now).empty());
        CHECK(!r6.control("origin 2", now).empty());
        CHECK(!r6.control("jump", now).empty());
    }
}

}  // namespace fieldbridge::test
