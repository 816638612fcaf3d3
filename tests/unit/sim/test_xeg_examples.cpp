// HIWIN XEG-C2: the manual's example exchanges (seed 001), byte for byte.
#include <doctest/doctest.h>

#include "models/xeg_model.hpp"
#include "sim_test_support.hpp"

namespace fieldbridge::test {
namespace {

struct Step {
    const char* what;
    const char* request;   // full ADU as printed (CRC included)
    const char* response;  // "" = no reply
    long long wait_ms;     // simulated time before the request
};

constexpr long long poll_gap_ms = 5;

}  // namespace

TEST_CASE("xeg: Appendix 1 quick start replays byte for byte with its timing") {
    // seed 001 Appendix 1, XEG-32 at ID 2; the table's "wait 30 s" and "wait 3 s" rows
    // are simulated time.
    const Step steps[] = {
        {"1-2 write model XEG-32", "02 10 06 00 00 01 02 0A 20 D3 D8", "02 10 06 00 00 01 01 72", 0},
        {"3-4 read model", "02 03 06 00 00 01 84 B1", "02 03 02 0A 20 FB 3C", poll_gap_ms},
        {"5-6 read firmware V3.0.1.884", "02 04 03 03 00 04 01 BE",
         "02 04 08 00 03 00 00 00 01 03 74 49 5E", poll_gap_ms},
        {"7-8 write reset", "02 10 06 10 00 01 02 00 01 17 F0", "02 10 06 10 00 01 00 B7", poll_gap_ms},
        {"9-10 status working", "02 04 03 01 00 01 60 7D", "02 04 02 00 01 3C F0", poll_gap_ms},
        {"11-13 wait 30 s, status idle", "02 04 03 01 00 01 60 7D", "02 04 02 00 00 FD 30", 30'000},
        {"14-15 write expert", "02 10 06 40 00 07 0E 00 00 03 E8 1F 40 01 F4 07 D0 00 64 00 01 E6 B8",
         "02 10 06 40 00 07 80 A4", poll_gap_ms},
        {"16-17 status working", "02 04 03 01 00 01 60 7D", "02 04 02 00 01 3C F0", poll_gap_ms},
        {"18-20 wait 3 s, status idle", "02 04 03 01 00 01 60 7D", "02 04 02 00 00 FD 30", 3'000},
        {"21-22 broadcast move, no reply", "00 10 06 30 00 03 06 0C 80 1F 40 00 01 3C A4", "", poll_gap_ms},
        {"23-24 status working", "02 04 03 01 00 01 60 7D", "02 04 02 00 01 3C F0", poll_gap_ms},
        {"25-27 wait 3 s, status positioned", "02 04 03 01 00 01 60 7D", "02 04 02 00 02 7C F1", 3'000},
    };
    SimClock clock;
    sim::XegModel xeg(2, {});
    for (const auto& step : steps) {
        clock.advance_ms(step.wait_ms);
        INFO(step.what);
        CHECK(exchange(xeg, hex(step.request), clock.now()) == step.response);
        // The position the scenario states at each "read status and position" row.
        const std::string what = step.what;
        if (what.rfind("11-13", 0) == 0) CHECK(xeg.position() == 3200);   // 32.00 mm
        if (what.rfind("18-20", 0) == 0) CHECK(xeg.position() == 1700);   // 17.00 mm
        if (what.rfind("25-27", 0) == 0) CHECK(xeg.position() == 3200);   // 32.00 mm
    }
}

TEST_CASE("xeg: section examples (FC02, FC03, FC04, FC07, FC10, FC06 error)") {
    SimClock clock;
    sim::XegModel xeg(2, {});

    SUBCASE("4.2.1 read 8 discrete inputs -> 22") {
        // The reply sets bits 1 and 5 (IN2, IN6): the manual's wiring for its example.
        REQUIRE(xeg.control("inputs 0x22", clock.now()).empty());
        CHECK(exchange(xeg, hex("02 02 00 00 00 08 79 FF"), clock.now()) == "02 02 01 22 21 D5");
    }
    SUBCASE("4.2.2 read the model") {
        CHECK(exchange(xeg, rtu("02 03 06 00 00 01"), clock.now()) == hex_of(rtu("02 03 02 0A 20")));
    }
    SUBCASE("4.2.3 read position and status: 20.00 mm, Pos") {
        REQUIRE(write_registers(xeg, 2, 0x0610, {1}, clock.now()) == "10 06 10 00 01");
        clock.advance_s(30);
        REQUIRE(write_registers(xeg, 2, 0x0630, {2000, 8000, 1}, clock.now()) == "10 06 30 00 03");
        clock.advance_s(3);
        CHECK(exchange(xeg, rtu("02 04 03 00 00 02"), clock.now()) == hex_of(rtu("02 04 04 07 D0 00 02")));
    }
    SUBCASE("4.2.4 read exception status -> 02 emergency stop") {
        REQUIRE(xeg.control("alarm 7", clock.now()).empty());
        CHECK(exchange(xeg, hex("02 07 41 12"), clock.now()) == "02 07 02 53 F1");
    }
    SUBCASE("4.2.5 write the expert block (after a reset)") {
        REQUIRE(write_registers(xeg, 2, 0x0610, {1}, clock.now()) == "10 06 10 00 01");
        clock.advance_s(30);
        CHECK(exchange(xeg, rtu("02 10 06 40 00 07 0E 00 00 03 E8 17 70 01 F4 03 E8 00 64 00 01"),
                       clock.now()) == hex_of(rtu("02 10 06 40 00 07")));
        // "automatically reset the value in the register address 0646h as 0"
        CHECK(read_registers(xeg, 2, 0x03, 0x0646, 1, clock.now()) == std::vector<std::uint16_t>{0});
        CHECK(xeg.status() == sim::XegStatus::working);
    }
    SUBCASE("5 FC06 to 0x0611 -> exception 02") {
        CHECK(exchange(xeg, hex("02 06 06 11 00 01 18 B4"), clock.now()) == "02 86 02 33 A1");
    }
}

TEST_CASE("xeg: exception codes of section 5") {
    SimClock clock;
    sim::XegModel xeg(2, {});
    SUBCASE("01: function codes the controller lacks") {
        CHECK(exchange(xeg, rtu("02 01 00 00 00 08"), clock.now()) == hex_of(rtu("02 81 01")));
        CHECK(exchange(xeg, rtu("02 05 00 00 FF 00"), clock.now()) == hex_of(rtu("02 85 01")));
        CHECK(exchange(xeg, rtu("02 11"), clock.now()) == hex_of(rtu("02 91 01")));
        // FC06 on an address of the map: not in the function table -> 01.
        CHECK(exchange(xeg, rtu("02 06 06 10 00 01"), clock.now()) == hex_of(rtu("02 86 01")));
    }
    SUBCASE("02: addresses outside the map") {
        CHECK(exchange(xeg, rtu("02 02 00 08 00 01"), clock.now()) == hex_of(rtu("02 82 02")));
        CHECK(exchange(xeg, rtu("02 02 00 00 00 10"), clock.now()) == hex_of(rtu("02 82 02")));
        CHECK(exchange(xeg, rtu("02 04 03 00 00 03"), clock.now()) == hex_of(rtu("02 84 02")));
        CHECK(exchange(xeg, rtu("02 03 06 02 00 01"), clock.now()) == hex_of(rtu("02 83 02")));
        CHECK(exchange(xeg, rtu("02 10 06 11 00 01 02 00 01"), clock.now()) == hex_of(rtu("02 90 02")));
    }
    SUBCASE("03: bad quantities and values out of the model's range") {
        CHECK(exchange(xeg, rtu("02 04 03 00 00 00"), clock.now()) == hex_of(rtu("02 84 03")));
        CHECK(exchange(xeg, rtu("02 10 06 00 00 01 04 0A 20 00 00"), clock.now()) == hex_of(rtu("02 90 03")));
        // XEG-32: stroke 32.00 mm, speed 80.00 mm/s, holding speed 20.00 mm/s, force 40-100 %.
        CHECK(write_registers(xeg, 2, 0x0630, {3201}, clock.now()) == "90 03");
        CHECK(write_registers(xeg, 2, 0x0631, {8001}, clock.now()) == "90 03");
        CHECK(write_registers(xeg, 2, 0x0644, {2001}, clock.now()) == "90 03");
        CHECK(write_registers(xeg, 2, 0x0600, {0x0A22}, clock.now()) == "90 03");
        CHECK(write_registers(xeg, 2, 0x0610, {2}, clock.now()) == "90 03");
        CHECK(write_registers(xeg, 2, 0x0640, {0, 100, 1000, 100, 100, 39, 1}, clock.now()) == "90 03");
        CHECK(write_registers(xeg, 2, 0x0630, {1000, 0, 1}, clock.now()) == "90 03");
    }
    SUBCASE("04: moving before a reset; FC07 tells why") {
        CHECK(write_registers(xeg, 2, 0x0630, {1000, 5000, 1}, clock.now()) == "90 04");
        CHECK(exchange(xeg, rtu("02 07"), clock.now()) == hex_of(rtu("02 07 07")));
        CHECK(write_registers(xeg, 2, 0x0640, {0, 100, 1000, 100, 100, 50, 1}, clock.now()) == "90 04");
        CHECK(exchange(xeg, rtu("02 07"), clock.now()) == hex_of(rtu("02 07 08")));
    }
    SUBCASE("no reply: other IDs, broadcast reads, bad CRC") {
        CHECK(exchange(xeg, rtu("03 04 03 01 00 01"), clock.now()).empty());
        CHECK(exchange(xeg, rtu("00 04 03 01 00 01"), clock.now()).empty());
        CHECK(exchange(xeg, hex("02 04 03 01 00 01 60 7E"), clock.now()).empty());
    }
}

}  // namespace fieldbridge::test
