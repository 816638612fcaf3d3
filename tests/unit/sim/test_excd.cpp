// EXCD203MB: the manual's examples (seed 002), the register table rules and motion.
#include <doctest/doctest.h>

#include "models/excd_model.hpp"
#include "sim_test_support.hpp"

namespace fieldbridge::test {
namespace {

using Values = std::vector<std::uint16_t>;

Values read(sim::ExcdModel& excd, std::uint16_t address, std::uint16_t count, Clock::time_point now) {
    return read_registers(excd, 1, 0x03, address, count, now);
}

std::int32_t position(sim::ExcdModel& excd, Clock::time_point now) {
    const Values v = read(excd, 0x0201, 2, now);
    return static_cast<std::int32_t>((static_cast<std::uint32_t>(v[0]) << 16) | v[1]);
}

}  // namespace

TEST_CASE("excd: manual examples byte for byte") {
    SimClock clock;
    sim::ExcdModel excd(1, {});
    // Section 3c: save after switching to Modbus mode. The manual shows no reply; the
    // simulator acknowledges it like any FC10.
    CHECK(exchange(excd, hex("01 10 03 03 00 01 02 00 00 95 63"), clock.now()) ==
          hex_of(rtu("01 10 03 03 00 01")));
    // Example 1: hdir = 1.
    CHECK(exchange(excd, hex("01 10 00 00 00 01 02 00 01 67 90"), clock.now()) == "01 10 00 00 00 01 01 C9");
    CHECK(read(excd, 0x0000, 1, clock.now()) == Values{1});
    // Example 2: solm+ = 800000, high word first.
    CHECK(exchange(excd, hex("01 10 00 14 00 02 04 00 0C 35 00 24 03"), clock.now()) ==
          "01 10 00 14 00 02 01 CC");
    CHECK(read(excd, 0x0014, 2, clock.now()) == Values{0x000C, 0x3500});
    // Example 3: rabs = 0 at power-up.
    CHECK(exchange(excd, hex("01 03 02 01 00 02 94 73"), clock.now()) == "01 03 04 00 00 00 00 FA 33");
    // Example 4: rin = 0x000F.
    CHECK(exchange(excd, hex("01 03 02 03 00 01 75 B2"), clock.now()) == "01 03 02 00 0F F8 40");
}

TEST_CASE("excd: low word first as a device option") {
    SimClock clock;
    sim::ExcdModel excd(1, sim::ExcdOptions{false});
    // The manual's sentence: 1,600,000 is written 6A00 0018.
    CHECK(exchange(excd, rtu("01 10 00 14 00 02 04 6A 00 00 18"), clock.now()) ==
          hex_of(rtu("01 10 00 14 00 02")));
    CHECK(read(excd, 0x0014, 2, clock.now()) == Values{0x6A00, 0x0018});
    REQUIRE(write_registers(excd, 1, 0x0100, {0x2710, 0x0000}, clock.now()) == "10 01 00 00 02");  // abs 10000
    clock.advance_s(10);
    CHECK(read(excd, 0x0201, 2, clock.now()) == Values{0x2710, 0x0000});
}

TEST_CASE("excd: addresses, pairs, ranges, functions") {
    SimClock clock;
    sim::ExcdModel excd(1, {});
    SUBCASE("unknown addresses -> 02") {
        CHECK(exchange(excd, rtu("01 03 02 0B 00 01"), clock.now()) == hex_of(rtu("01 83 02")));
        CHECK(exchange(excd, rtu("01 03 00 3D 00 01"), clock.now()) == hex_of(rtu("01 83 02")));
        CHECK(exchange(excd, rtu("01 03 00 3C 00 02"), clock.now()) == hex_of(rtu("01 83 02")));
        CHECK(exchange(excd, rtu("01 06 04 F9 00 00"), clock.now()) == hex_of(rtu("01 86 02")));
        CHECK(exchange(excd, rtu("01 06 04 00 00 00"), clock.now()) == hex_of(rtu("01 86 02")));
    }
    SUBCASE("half a pair: writes -> 02, reads allowed") {
        CHECK(exchange(excd, rtu("01 06 00 14 00 01"), clock.now()) == hex_of(rtu("01 86 02")));
        CHECK(exchange(excd, rtu("01 06 00 15 00 01"), clock.now()) == hex_of(rtu("01 86 02")));
        CHECK(exchange(excd, rtu("01 10 00 15 00 02 04 00 00 00 01"), clock.now()) == hex_of(rtu("01 90 02")));
        CHECK(exchange(excd, rtu("01 10 00 13 00 02 04 00 01 00 0C"), clock.now()) == hex_of(rtu("01 90 02")));
        CHECK(read(excd, 0x0015, 1, clock.now()) == Values{0xA5E0});  // low half of 8,300,000
        // Nothing of a rejected write is applied.
        CHECK(read(excd, 0x0013, 1, clock.now()) == Values{0});
    }
    SUBCASE("read-only queries -> 02") {
        CHECK(exchange(excd, rtu("01 06 02 05 00 00"), clock.now()) == hex_of(rtu("01 86 02")));
        CHECK(exchange(excd, rtu("01 10 02 0C 00 02 04 00 00 00 00"), clock.now()) == hex_of(rtu("01 90 02")));
    }
    SUBCASE("values out of the manual's range -> 03") {
        CHECK(write_registers(excd, 1, 0x0000, {2}, clock.now(), true) == "86 03");
        CHECK(write_registers(excd, 1, 0x0012, {9}, clock.now(), true) == "86 03");
        CHECK(write_registers(excd, 1, 0x000F, {0x0007, 0xA121}, clock.now()) == "90 03");  // svr > 500000
        CHECK(write_registers(excd, 1, 0x0100, {0x007E, 0xA5E1}, clock.now()) == "90 03");  // abs > 8.3M
        CHECK(write_registers(excd, 1, 0x0100, {0xFF81, 0x5A1F}, clock.now()) == "90 03");  // abs < -8.3M
        CHECK(write_registers(excd, 1, 0x0106, {1}, clock.now(), true) == "86 03");         // start takes 0
        CHECK(write_registers(excd, 1, 0x0300, {0x10}, clock.now(), true) == "86 03");
    }
    SUBCASE("only FC03 / FC06 / FC10 -> others 01") {
        CHECK(exchange(excd, rtu("01 04 02 01 00 02"), clock.now()) == hex_of(rtu("01 84 01")));
        CHECK(exchange(excd, rtu("01 01 00 00 00 01"), clock.now()) == hex_of(rtu("01 81 01")));
        CHECK(exchange(excd, rtu("01 07"), clock.now()) == hex_of(rtu("01 87 01")));
    }
    SUBCASE("broadcast 0xFF acts without a reply; 0 and other IDs are ignored") {
        CHECK(exchange(excd, rtu("FF 10 00 00 00 01 02 00 01"), clock.now()).empty());
        CHECK(read(excd, 0x0000, 1, clock.now()) == Values{1});
        CHECK(exchange(excd, rtu("00 06 00 00 00 00"), clock.now()).empty());
        CHECK(exchange(excd, rtu("02 06 00 00 00 00"), clock.now()).empty());
        CHECK(read(excd, 0x0000, 1, clock.now()) == Values{1});
    }
}

TEST_CASE("excd: motion at svr, rby, stop, home, jog, soft limits") {
    SimClock clock;
    sim::ExcdModel excd(1, {});
    // svr = 10000 pulses/s at power-up.
    REQUIRE(write_registers(excd, 1, 0x0100, {0x0000, 0x4E20}, clock.now()) == "10 01 00 00 02");  // abs 20000
    CHECK(read(excd, 0x0205, 1, clock.now()) == Values{0});  // busy
    CHECK(read(excd, 0x0200, 1, clock.now()) == Values{10000});  // rms: running speed
    clock.advance_ms(500);
    CHECK(position(excd, clock.now()) == 5000);
    clock.advance_ms(1500);
    CHECK(position(excd, clock.now()) == 20000);
    CHECK(read(excd, 0x0205, 1, clock.now()) == Values{1});
    CHECK(read(excd, 0x02D4, 2, clock.now()) == Values{0, 20000});  // renc follows rabs

    // rel -5000 at a new svr of 1000 pulses/s.
    REQUIRE(write_registers(excd, 1, 0x000F, {0, 1000}, clock.now()) == "10 00 0F 00 02");
    REQUIRE(write_registers(excd, 1, 0x0104, {0xFFFF, 0xEC78}, clock.now()) == "10 01 04 00 02");
    clock.advance_s(2);
    CHECK(position(excd, clock.now()) == 18000);
    REQUIRE(write_registers(excd, 1, 0x0108, {0}, clock.now(), true) == "06 01 08 00 00");  // stop
    clock.advance_s(10);
    CHECK(position(excd, clock.now()) == 18000);
    CHECK(read(excd, 0x0205, 1, clock.now()) == Values{1});

    // sabs + start.
    REQUIRE(write_registers(excd, 1, 0x0102, {0, 19000}, clock.now()) == "10 01 02 00 02");
    clock.advance_s(1);
    CHECK(position(excd, clock.now()) == 18000);
    REQUIRE(write_registers(excd, 1, 0x0106, {0}, clock.now(), true) == "06 01 06 00 00");
    clock.advance_s(1);
    CHECK(position(excd, clock.now()) == 19000);

    // home at hvr = 2000 pulses/s; the home sensor reads 1 at 0.
    REQUIRE(write_registers(excd, 1, 0x0107, {0}, clock.now(), true) == "06 01 07 00 00");
    clock.advance_s(5);
    CHECK(position(excd, clock.now()) == 9000);
    CHECK(read(excd, 0x0206, 1, clock.now()) == Values{0});
    clock.advance_s(5);
    CHECK(position(excd, clock.now()) == 0);
    CHECK(read(excd, 0x0206, 1, clock.now()) == Values{1});

    // jog: one pulse each way, then continuous forward against a soft limit of 3000.
    REQUIRE(write_registers(excd, 1, 0x010A, {0, 1}, clock.now()) == "10 01 0A 00 02");
    clock.advance_s(1);
    CHECK(position(excd, clock.now()) == 1);
    REQUIRE(write_registers(excd, 1, 0x010A, {0xFFFF, 0xFFFF}, clock.now()) == "10 01 0A 00 02");
    clock.advance_s(1);
    CHECK(position(excd, clock.now()) == 0);
    REQUIRE(write_registers(excd, 1, 0x0013, {1, 0, 3000}, clock.now()) == "10 00 13 00 03");
    REQUIRE(write_registers(excd, 1, 0x010A, {0x007E, 0xA5E0}, clock.now()) == "10 01 0A 00 02");
    clock.advance_ms(1500);  // jvr = 1000 pulses/s
    CHECK(position(excd, clock.now()) == 1500);
    CHECK(read(excd, 0x0205, 1, clock.now()) == Values{0});
    clock.advance_s(5);
    CHECK(position(excd, clock.now()) == 3000);
    // continuous reverse, ended by jogstop
    REQUIRE(write_registers(excd, 1, 0x010A, {0xFF81, 0x5A20}, clock.now()) == "10 01 0A 00 02");
    clock.advance_s(1);
    REQUIRE(write_registers(excd, 1, 0x010C, {0}, clock.now(), true) == "06 01 0C 00 00");
    clock.advance_s(1);
    CHECK(position(excd, clock.now()) == 2000);
    CHECK(read(excd, 0x0205, 1, clock.now()) == Values{1});
}

TEST_CASE("excd: alarm, IO, counters, variables, version") {
    SimClock clock;
    sim::ExcdModel excd(1, {});
    SUBCASE("an alarm stops and refuses motion; stop still works") {
        REQUIRE(write_registers(excd, 1, 0x0100, {0, 50000}, clock.now()) == "10 01 00 00 02");
        clock.advance_s(1);
        REQUIRE(excd.control("alarm 7", clock.now()).empty());
        CHECK(read(excd, 0x02D6, 1, clock.now()) == Values{7});
        CHECK(read(excd, 0x0205, 1, clock.now()) == Values{1});
        CHECK(write_registers(excd, 1, 0x0100, {0, 0}, clock.now()) == "90 04");
        CHECK(write_registers(excd, 1, 0x0107, {0}, clock.now(), true) == "86 04");
        CHECK(write_registers(excd, 1, 0x0108, {0}, clock.now(), true) == "06 01 08 00 00");
        REQUIRE(excd.control("clear", clock.now()).empty());
        CHECK(read(excd, 0x02D6, 1, clock.now()) == Values{0});
        CHECK(write_registers(excd, 1, 0x0100, {0, 0}, clock.now()) == "10 01 00 00 02");
    }
    SUBCASE("outon / outoff / clear drive rout; inputs drive rin") {
        REQUIRE(write_registers(excd, 1, 0x0300, {0x5}, clock.now(), true) == "06 03 00 00 05");
        REQUIRE(write_registers(excd, 1, 0x0300, {0x2}, clock.now(), true) == "06 03 00 00 02");
        CHECK(read(excd, 0x0204, 1, clock.now()) == Values{0x7});
        REQUIRE(write_registers(excd, 1, 0x0302, {0x1}, clock.now(), true) == "06 03 02 00 01");
        CHECK(read(excd, 0x0204, 1, clock.now()) == Values{0x6});
        REQUIRE(write_registers(excd, 1, 0x0301, {0}, clock.now(), true) == "06 03 01 00 00");
        CHECK(read(excd, 0x0204, 1, clock.now()) == Values{0});
        REQUIRE(excd.control("inputs 0x3", clock.now()).empty());
        CHECK(read(excd, 0x0203, 1, clock.now()) == Values{3});
    }
    SUBCASE("cnt writes a counter, rcount reads it, rstcount clears it") {
        REQUIRE(write_registers(excd, 1, 0x0272, {0xFFFF, 0xFFFE}, clock.now()) == "10 02 72 00 02");  // cnt2 = -2
        CHECK(read(excd, 0x020E, 2, clock.now()) == Values{0xFFFF, 0xFFFE});                     // rcount2
        CHECK(read(excd, 0x020C, 2, clock.now()) == Values{0, 0});                               // rcount1
        REQUIRE(write_registers(excd, 1, 0x04C8, {0}, clock.now(), true) == "06 04 C8 00 00");     // rstcount2
        CHECK(read(excd, 0x020E, 2, clock.now()) == Values{0, 0});
    }
    SUBCASE("variables n01-n99 and the version") {
        REQUIRE(write_registers(excd, 1, 0x04C5, {0x0001, 0x0002}, clock.now()) == "10 04 C5 00 02");  // n99
        CHECK(read(excd, 0x04C5, 2, clock.now()) == Values{1, 2});
        CHECK(read(excd, 0x0207, 2, clock.now()) == Values{0, 120});
        CHECK(read(excd, 0x0209, 2, clock.now()) == Values{0, 0});  // rse, rsa
    }
    SUBCASE("control errors and constructor checks") {
        CHECK(!excd.control("alarm 0", clock.now()).empty());
        CHECK(!excd.control("inputs -1", clock.now()).empty());
        CHECK(!excd.control("dance", clock.now()).empty());
        CHECK_THROWS_AS(sim::ExcdModel(0, {}), std::invalid_argument);
        CHECK_THROWS_AS(sim::ExcdModel(255, {}), std::invalid_argument);
    }
}

}  // namespace fieldbridge::test
