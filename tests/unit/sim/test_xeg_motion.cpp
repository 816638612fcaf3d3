// HIWIN XEG-C2: motion over simulated time, objects, alarms, the DO bits.
#include <doctest/doctest.h>

#include "models/xeg_model.hpp"
#include "sim_test_support.hpp"

namespace fieldbridge::test {
namespace {

using sim::XegStatus;

/// DO bits 0x0010-0x0017 as a byte (POS HOLD BUSY ALM1 ALM2 CHK1-3).
std::string outputs(sim::XegModel& xeg, Clock::time_point now) {
    return exchange(xeg, rtu("02 02 00 10 00 08"), now);
}

void reset_and_wait(sim::XegModel& xeg, SimClock& clock) {
    REQUIRE(write_registers(xeg, 2, 0x0610, {1}, clock.now()) == "10 06 10 00 01");
    clock.advance_s(30);
    xeg.advance(clock.now());
    REQUIRE(xeg.status() == XegStatus::idle);
}

}  // namespace

TEST_CASE("xeg: reset homes to the open end at 10 mm/s") {
    SimClock clock;
    sim::XegModel xeg(2, {});  // XEG-32
    CHECK(xeg.position() == 0);
    REQUIRE(write_registers(xeg, 2, 0x0610, {1}, clock.now()) == "10 06 10 00 01");
    CHECK(xeg.status() == XegStatus::working);
    CHECK(outputs(xeg, clock.now()) == hex_of(rtu("02 02 01 04")));  // BUSY
    clock.advance_ms(1600);
    xeg.advance(clock.now());
    CHECK(xeg.position() == 1600);
    CHECK(xeg.status() == XegStatus::working);
    clock.advance_ms(1600);
    xeg.advance(clock.now());
    CHECK(xeg.position() == 3200);
    CHECK(xeg.status() == XegStatus::idle);
    CHECK(read_registers(xeg, 2, 0x04, 0x0300, 2, clock.now()) == std::vector<std::uint16_t>{3200, 0});
}

TEST_CASE("xeg: move at the commanded speed ends positioned") {
    SimClock clock;
    sim::XegModel xeg(2, {});
    reset_and_wait(xeg, clock);
    REQUIRE(write_registers(xeg, 2, 0x0630, {1200, 4000, 1}, clock.now()) == "10 06 30 00 03");
    CHECK(read_registers(xeg, 2, 0x03, 0x0630, 3, clock.now()) == std::vector<std::uint16_t>{1200, 4000, 0});
    clock.advance_ms(250);  // 40 mm/s: 10 mm in 0.25 s
    xeg.advance(clock.now());
    CHECK(xeg.position() == 2200);
    CHECK(xeg.status() == XegStatus::working);
    clock.advance_ms(250);
    CHECK(read_registers(xeg, 2, 0x04, 0x0300, 2, clock.now()) == std::vector<std::uint16_t>{1200, 2});
    CHECK(outputs(xeg, clock.now()) == hex_of(rtu("02 02 01 01")));  // POS
}

TEST_CASE("xeg: expert closing onto an object holds it") {
    SimClock clock;
    sim::XegModel xeg(2, {});
    reset_and_wait(xeg, clock);
    REQUIRE(xeg.control("object 20.0", clock.now()).empty());
    // inward 10 mm at 80 mm/s (to 22.00), then hold 5 mm at 20 mm/s: meets 20.00 mm.
    REQUIRE(write_registers(xeg, 2, 0x0640, {0, 1000, 8000, 500, 2000, 100, 1}, clock.now()) ==
            "10 06 40 00 07");
    clock.advance_ms(125 + 50);
    xeg.advance(clock.now());
    CHECK(xeg.position() == 2100);
    CHECK(xeg.status() == XegStatus::working);
    clock.advance_ms(100);
    CHECK(read_registers(xeg, 2, 0x04, 0x0300, 2, clock.now()) == std::vector<std::uint16_t>{2000, 3});
    CHECK(outputs(xeg, clock.now()) == hex_of(rtu("02 02 01 02")));  // HOLD
}

TEST_CASE("xeg: a closing move that meets an object raises the move alarm") {
    SimClock clock;
    sim::XegModel xeg(2, {});
    reset_and_wait(xeg, clock);
    REQUIRE(xeg.control("object 25.5", clock.now()).empty());
    REQUIRE(write_registers(xeg, 2, 0x0630, {1000, 8000, 1}, clock.now()) == "10 06 30 00 03");
    clock.advance_s(1);
    CHECK(read_registers(xeg, 2, 0x04, 0x0300, 2, clock.now()) == std::vector<std::uint16_t>{2550, 5});
    CHECK(outputs(xeg, clock.now()) == hex_of(rtu("02 02 01 08")));  // ALM1
    CHECK(exchange(xeg, rtu("02 07"), clock.now()) == hex_of(rtu("02 07 10")));
    // Further motion is refused until a reset clears the alarm.
    CHECK(write_registers(xeg, 2, 0x0630, {3000, 8000, 1}, clock.now()) == "90 04");
    reset_and_wait(xeg, clock);
    CHECK(exchange(xeg, rtu("02 07"), clock.now()) == hex_of(rtu("02 07 00")));
    CHECK(write_registers(xeg, 2, 0x0630, {3000, 8000, 1}, clock.now()) == "10 06 30 00 03");
}

TEST_CASE("xeg: expert past the closed end stops there with the position alarm") {
    SimClock clock;
    sim::XegModel xeg(2, {});
    reset_and_wait(xeg, clock);
    REQUIRE(write_registers(xeg, 2, 0x0640, {0, 3000, 8000, 500, 2000, 100, 1}, clock.now()) ==
            "10 06 40 00 07");
    clock.advance_s(3);
    CHECK(read_registers(xeg, 2, 0x04, 0x0300, 2, clock.now()) == std::vector<std::uint16_t>{0, 4});
    CHECK(exchange(xeg, rtu("02 07"), clock.now()) == hex_of(rtu("02 07 11")));
}

TEST_CASE("xeg: stop ends the motion where it is") {
    SimClock clock;
    sim::XegModel xeg(2, {});
    reset_and_wait(xeg, clock);
    REQUIRE(write_registers(xeg, 2, 0x0630, {0, 1000, 1}, clock.now()) == "10 06 30 00 03");
    clock.advance_ms(500);
    REQUIRE(write_registers(xeg, 2, 0x0620, {1}, clock.now()) == "10 06 20 00 01");
    clock.advance_s(5);
    CHECK(read_registers(xeg, 2, 0x04, 0x0300, 2, clock.now()) == std::vector<std::uint16_t>{2700, 0});
    CHECK(read_registers(xeg, 2, 0x03, 0x0620, 1, clock.now()) == std::vector<std::uint16_t>{0});
}

TEST_CASE("xeg: injected alarms, FC07 codes and clear") {
    SimClock clock;
    sim::XegModel xeg(2, {});
    reset_and_wait(xeg, clock);
    const struct {
        const char* command;
        std::uint16_t status;
        const char* fc07;
        const char* outputs;
    } alarms[] = {
        {"alarm 4", 4, "02 07 11", "02 02 01 08"},
        {"alarm 5", 5, "02 07 10", "02 02 01 08"},
        {"alarm 6", 6, "02 07 12", "02 02 01 08"},
        {"alarm 7", 7, "02 07 02", "02 02 01 10"},
    };
    for (const auto& a : alarms) {
        INFO(a.command);
        REQUIRE(xeg.control(a.command, clock.now()).empty());
        CHECK(read_registers(xeg, 2, 0x04, 0x0301, 1, clock.now()) == std::vector<std::uint16_t>{a.status});
        CHECK(exchange(xeg, rtu("02 07"), clock.now()) == hex_of(rtu(a.fc07)));
        CHECK(outputs(xeg, clock.now()) == hex_of(rtu(a.outputs)));
        CHECK(write_registers(xeg, 2, 0x0630, {1000, 1000, 1}, clock.now()) == "90 04");
        REQUIRE(xeg.control("clear", clock.now()).empty());
        CHECK(read_registers(xeg, 2, 0x04, 0x0301, 1, clock.now()) == std::vector<std::uint16_t>{0});
        if (a.status == 6) reset_and_wait(xeg, clock);  // a homing failure needs a new reset
    }
    // The emergency stop also refuses a reset.
    REQUIRE(xeg.control("alarm 7", clock.now()).empty());
    CHECK(write_registers(xeg, 2, 0x0610, {1}, clock.now()) == "90 04");
    CHECK(!xeg.control("alarm 3", clock.now()).empty());
    CHECK(!xeg.control("object 33", clock.now()).empty());
    CHECK(!xeg.control("fly", clock.now()).empty());
}

TEST_CASE("xeg: busy, wrong gripper type, indirect data, broadcast") {
    SimClock clock;
    sim::XegModel xeg(2, {});
    reset_and_wait(xeg, clock);
    SUBCASE("a move while working is refused (4.2.5)") {
        REQUIRE(write_registers(xeg, 2, 0x0630, {0, 100, 1}, clock.now()) == "10 06 30 00 03");
        CHECK(write_registers(xeg, 2, 0x0630, {3200, 100, 1}, clock.now()) == "90 04");
        CHECK(exchange(xeg, rtu("02 07"), clock.now()) == hex_of(rtu("02 07 07")));
    }
    SUBCASE("a model code that is not the connected gripper") {
        REQUIRE(write_registers(xeg, 2, 0x0600, {0x0A40}, clock.now()) == "10 06 00 00 01");
        CHECK(write_registers(xeg, 2, 0x0630, {1000, 1000, 1}, clock.now()) == "90 04");
        CHECK(exchange(xeg, rtu("02 07"), clock.now()) == hex_of(rtu("02 07 04")));
    }
    SUBCASE("indirect data 21 of 63 moves to a third of the stroke") {
        REQUIRE(write_registers(xeg, 2, 0x0601, {21}, clock.now()) == "10 06 01 00 01");
        CHECK(read_registers(xeg, 2, 0x03, 0x0601, 1, clock.now()) == std::vector<std::uint16_t>{0});
        clock.advance_s(2);
        CHECK(read_registers(xeg, 2, 0x04, 0x0300, 2, clock.now()) == std::vector<std::uint16_t>{1066, 2});
        CHECK(write_registers(xeg, 2, 0x0601, {64}, clock.now()) == "90 03");
    }
    SUBCASE("broadcast FC10 acts without a reply") {
        CHECK(exchange(xeg, rtu("00 10 06 30 00 03 06 03 E8 1F 40 00 01"), clock.now()).empty());
        clock.advance_s(1);
        CHECK(read_registers(xeg, 2, 0x04, 0x0300, 2, clock.now()) == std::vector<std::uint16_t>{1000, 2});
    }
}

TEST_CASE("xeg: XEG-16 ranges and bad options") {
    SimClock clock;
    sim::XegModel xeg(2, sim::XegOptions{0x0A10});
    CHECK(read_registers(xeg, 2, 0x03, 0x0600, 1, clock.now()) == std::vector<std::uint16_t>{0x0A10});
    CHECK(write_registers(xeg, 2, 0x0630, {1601}, clock.now()) == "90 03");
    CHECK(write_registers(xeg, 2, 0x0631, {6001}, clock.now()) == "90 03");
    CHECK(write_registers(xeg, 2, 0x0630, {1600, 6000}, clock.now()) == "10 06 30 00 02");
    CHECK_THROWS_AS(sim::XegModel(0, {}), std::invalid_argument);
    CHECK_THROWS_AS(sim::XegModel(16, {}), std::invalid_argument);
    CHECK_THROWS_AS(sim::XegModel(1, sim::XegOptions{0x0A99}), std::invalid_argument);
}

}  // namespace fieldbridge::test
