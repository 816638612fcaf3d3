// WTEC-485 in Modbus-RTU mode: the manual's examples (seed 003 part 2) and the rules.
#include <doctest/doctest.h>

#include "models/wtec_rtu_model.hpp"
#include "sim_test_support.hpp"

namespace fieldbridge::test {
namespace {

using Values = std::vector<std::uint16_t>;

std::uint16_t reg(sim::WtecRtuModel& wtec, std::uint16_t address, Clock::time_point now,
                  std::uint8_t unit = 1) {
    return read_registers(wtec, unit, 0x03, address, 1, now).at(0);
}

}  // namespace

TEST_CASE("wtec-rtu: manual examples byte for byte, in a working order") {
    SimClock clock;
    sim::WtecRtuModel wtec(1, 20000);
    // Read init state before initializing: 0.
    CHECK(exchange(wtec, hex("01 03 02 00 00 01 85 B2"), clock.now()) == "01 03 02 00 00 B8 44");
    // Instant position (the manual prints the request without its function code).
    CHECK(exchange(wtec, hex("01 03 02 04 00 01 C4 73"), clock.now()) == "01 03 02 00 00 B8 44");
    // Initialize.
    CHECK(exchange(wtec, hex("01 06 01 00 00 01 49 F6"), clock.now()) == "01 06 01 00 00 01 49 F6");
    CHECK(reg(wtec, 0x0200, clock.now()) == 9);  // homing
    clock.advance_ms(300);
    CHECK(reg(wtec, 0x0200, clock.now()) == 1);
    CHECK(reg(wtec, 0x0202, clock.now()) == 1);
    // Force 80 %, then 100 % (the reads are "xx xx" in the manual). Force is the N max
    // (grip) current over R's max current 0x3F: 80 % sets N max = round(50.4) = 50,
    // which reads round(5000 / 63) = 79 %; 100 % sets 63 and reads 100 %.
    CHECK(exchange(wtec, hex("01 06 01 03 00 50 78 0A"), clock.now()) == "01 06 01 03 00 50 78 0A");
    CHECK(wtec.gripper().gripper_params().max_current == 50);
    CHECK(exchange(wtec, hex("01 03 01 03 00 01 75 F6"), clock.now()) == hex_of(rtu("01 03 02 00 4F")));
    CHECK(exchange(wtec, hex("01 06 01 03 00 64 79 DD"), clock.now()) == "01 06 01 03 00 64 79 DD");
    CHECK(wtec.gripper().gripper_params().max_current == 0x3F);
    CHECK(reg(wtec, 0x0103, clock.now()) == 100);
    // Position 50, read back the set position, follow the instant position.
    CHECK(exchange(wtec, hex("01 06 01 05 00 32 19 E2"), clock.now()) == "01 06 01 05 00 32 19 E2");
    CHECK(exchange(wtec, hex("01 03 01 05 00 01 95 F7"), clock.now()) == hex_of(rtu("01 03 02 00 32")));
    CHECK(reg(wtec, 0x0202, clock.now()) == 0);  // moving
    clock.advance_ms(125);                         // 40000 counts/s at speed 100 %
    CHECK(reg(wtec, 0x0204, clock.now()) == 25);
    clock.advance_ms(125);
    CHECK(reg(wtec, 0x0204, clock.now()) == 50);
    CHECK(reg(wtec, 0x0202, clock.now()) == 1);
    // Speed 50 %.
    CHECK(exchange(wtec, hex("01 06 01 04 00 32 48 22"), clock.now()) == "01 06 01 04 00 32 48 22");
    CHECK(exchange(wtec, hex("01 03 01 04 00 01 C4 37"), clock.now()) == hex_of(rtu("01 03 02 00 32")));
    // Grip an object 30 % wide: closing to 100 % stops at 70 %, grip state 2.
    REQUIRE(wtec.control("object 30", clock.now()).empty());
    REQUIRE(write_registers(wtec, 1, 0x0105, {100}, clock.now(), true) == "06 01 05 00 64");
    clock.advance_s(1);
    CHECK(exchange(wtec, hex("01 03 02 02 00 01 24 72"), clock.now()) == "01 03 02 00 02 39 85");
    CHECK(reg(wtec, 0x0204, clock.now()) == 70);
    // Init direction, save.
    CHECK(exchange(wtec, hex("01 06 03 00 00 01 48 4E"), clock.now()) == "01 06 03 00 00 01 48 4E");
    CHECK(exchange(wtec, hex("01 06 03 02 00 01 E9 8E"), clock.now()) == "01 06 03 02 00 01 E9 8E");
    CHECK(reg(wtec, 0x0302, clock.now()) == 1);
    // Emergency stop: latched, motor released, only initialization unlocks it.
    CHECK(exchange(wtec, hex("01 06 01 02 00 01 E8 36"), clock.now()) == "01 06 01 02 00 01 E8 36");
    CHECK(reg(wtec, 0x0102, clock.now()) == 1);
    CHECK(reg(wtec, 0x0202, clock.now()) == 11);
    CHECK(write_registers(wtec, 1, 0x0105, {10}, clock.now(), true) == "86 04");
    REQUIRE(write_registers(wtec, 1, 0x0100, {1}, clock.now(), true) == "06 01 00 00 01");
    CHECK(reg(wtec, 0x0102, clock.now()) == 0);
    // Device ID 5: the reply already comes from ID 5.
    CHECK(exchange(wtec, hex("01 06 03 03 00 05 B9 8D"), clock.now()) == "05 06 03 03 00 05 B8 09");
    CHECK(exchange(wtec, hex("01 03 02 00 00 01 85 B2"), clock.now()).empty());
    CHECK(reg(wtec, 0x0303, clock.now(), 5) == 5);
}

TEST_CASE("wtec-rtu: exceptions and broadcast") {
    SimClock clock;
    sim::WtecRtuModel wtec(1, 20000);
    SUBCASE("01: only FC03 and FC06") {
        CHECK(exchange(wtec, rtu("01 04 02 00 00 01"), clock.now()) == hex_of(rtu("01 84 01")));
        CHECK(exchange(wtec, rtu("01 10 01 03 00 01 02 00 50"), clock.now()) == hex_of(rtu("01 90 01")));
    }
    SUBCASE("02: outside the blocks, or a write without a meaning") {
        CHECK(exchange(wtec, rtu("01 03 01 06 00 01"), clock.now()) == hex_of(rtu("01 83 02")));
        CHECK(exchange(wtec, rtu("01 03 02 04 00 03"), clock.now()) == hex_of(rtu("01 83 02")));
        CHECK(exchange(wtec, rtu("01 03 00 00 00 01"), clock.now()) == hex_of(rtu("01 83 02")));
        CHECK(exchange(wtec, rtu("01 06 02 00 00 01"), clock.now()) == hex_of(rtu("01 86 02")));
        CHECK(exchange(wtec, rtu("01 06 01 01 00 01"), clock.now()) == hex_of(rtu("01 86 02")));
        // Inside a block the undefined addresses read 0: one read covers 0x0200-0x0204.
        CHECK(read_registers(wtec, 1, 0x03, 0x0200, 5, clock.now()) == Values{0, 0, 11, 0, 0});
    }
    SUBCASE("03: values out of range") {
        CHECK(write_registers(wtec, 1, 0x0100, {2}, clock.now(), true) == "86 03");
        CHECK(write_registers(wtec, 1, 0x0102, {0}, clock.now(), true) == "86 03");
        CHECK(write_registers(wtec, 1, 0x0103, {19}, clock.now(), true) == "86 03");
        CHECK(write_registers(wtec, 1, 0x0103, {101}, clock.now(), true) == "86 03");
        CHECK(write_registers(wtec, 1, 0x0104, {0}, clock.now(), true) == "86 03");
        CHECK(write_registers(wtec, 1, 0x0105, {101}, clock.now(), true) == "86 03");
        CHECK(write_registers(wtec, 1, 0x0300, {3}, clock.now(), true) == "86 03");
        CHECK(write_registers(wtec, 1, 0x0302, {2}, clock.now(), true) == "86 03");
        CHECK(write_registers(wtec, 1, 0x0303, {0}, clock.now(), true) == "86 03");
        CHECK(write_registers(wtec, 1, 0x0303, {248}, clock.now(), true) == "86 03");
    }
    SUBCASE("04: a position before initializing") {
        CHECK(write_registers(wtec, 1, 0x0105, {50}, clock.now(), true) == "86 04");
    }
    SUBCASE("broadcast acts without a reply") {
        CHECK(exchange(wtec, rtu("00 06 01 00 00 01"), clock.now()).empty());
        clock.advance_s(1);
        CHECK(reg(wtec, 0x0200, clock.now()) == 1);
        CHECK(exchange(wtec, rtu("00 03 02 00 00 01"), clock.now()).empty());
    }
    SUBCASE("a failed homing reads 2; clear returns to 0") {
        REQUIRE(wtec.control("fail-homing", clock.now()).empty());
        REQUIRE(write_registers(wtec, 1, 0x0100, {1}, clock.now(), true) == "06 01 00 00 01");
        clock.advance_s(1);
        CHECK(reg(wtec, 0x0200, clock.now()) == 2);
        CHECK(write_registers(wtec, 1, 0x0105, {50}, clock.now(), true) == "86 04");
        REQUIRE(wtec.control("clear", clock.now()).empty());
        CHECK(reg(wtec, 0x0200, clock.now()) == 0);
    }
    SUBCASE("constructor and control checks") {
        CHECK_THROWS_AS(sim::WtecRtuModel(0, 20000), std::invalid_argument);
        CHECK_THROWS_AS(sim::WtecRtuModel(248, 20000), std::invalid_argument);
        CHECK_THROWS_AS(sim::WtecRtuModel(1, 10), std::invalid_argument);
        CHECK(!wtec.control("object 101", clock.now()).empty());
        CHECK(!wtec.control("position x", clock.now()).empty());
        CHECK(!wtec.control("jump", clock.now()).empty());
    }
}

TEST_CASE("wtec-rtu: init direction closed homes at the closed end") {
    SimClock clock;
    sim::WtecRtuModel wtec(1, 20000);
    REQUIRE(write_registers(wtec, 1, 0x0300, {2}, clock.now(), true) == "06 03 00 00 02");
    REQUIRE(write_registers(wtec, 1, 0x0100, {1}, clock.now(), true) == "06 01 00 00 01");
    clock.advance_s(2);
    REQUIRE(reg(wtec, 0x0200, clock.now()) == 1);
    // Positions now count from the closed end: 100 % is fully open, and closing toward
    // 0 meets an object 40 % wide at 40 %.
    REQUIRE(write_registers(wtec, 1, 0x0105, {100}, clock.now(), true) == "06 01 05 00 64");
    clock.advance_s(1);
    CHECK(reg(wtec, 0x0204, clock.now()) == 100);
    REQUIRE(wtec.control("object 40", clock.now()).empty());
    REQUIRE(write_registers(wtec, 1, 0x0105, {0}, clock.now(), true) == "06 01 05 00 00");
    clock.advance_s(1);
    CHECK(reg(wtec, 0x0204, clock.now()) == 40);
    CHECK(reg(wtec, 0x0202, clock.now()) == 2);
}

}  // namespace fieldbridge::test
