// One physical WTEC-485 gripper, two faces: the same scenario driven through the
// Modbus-RTU face and through the ASCII face must show the same state in the uniform
// register view (0x0200 init state, 0x0202 grip state, 0x0204 position %).
#include <doctest/doctest.h>

#include "models/wtec_ascii_model.hpp"
#include "models/wtec_rtu_model.hpp"
#include "protocol/wtec_ascii_commands.hpp"
#include "sim_test_support.hpp"

namespace fieldbridge::test {
namespace {

namespace wtec = protocol::wtec;
constexpr std::uint32_t stroke = 20000;

struct View {
    std::uint16_t init_state = 0;
    std::uint16_t grip_state = 0;
    std::uint16_t position_percent = 0;
    bool operator==(const View&) const = default;
};

std::ostream& operator<<(std::ostream& out, const View& v) {
    return out << "{init " << v.init_state << ", grip " << v.grip_state << ", position "
               << v.position_percent << "%}";
}

View rtu_view(sim::WtecRtuModel& rtu_face, Clock::time_point now) {
    const auto init = read_registers(rtu_face, 1, 0x03, 0x0200, 1, now).at(0);
    const auto state = read_registers(rtu_face, 1, 0x03, 0x0202, 3, now);
    return {init, state.at(0), state.at(2)};
}

wtec::Reply ask(sim::WtecAsciiModel& ascii_face, const wtec::Command& command, Clock::time_point now) {
    const std::string request = wtec::encode_frame_body(wtec::encode_command(1, command));
    const auto reply = ascii_face.on_frame(ascii(request), now);
    REQUIRE(reply.has_value());
    const auto frame = wtec::scan_frame(*reply);
    REQUIRE(frame.complete());
    const auto decoded = wtec::decode_reply(1, command, frame.value);
    REQUIRE(decoded.complete());
    return decoded.value;
}

View ascii_view(sim::WtecAsciiModel& ascii_face, Clock::time_point now) {
    const auto g = std::get<wtec::StateCode>(ask(ascii_face, wtec::QueryHoming{}, now)).code;
    const auto d = std::get<wtec::StateCode>(ask(ascii_face, wtec::QueryGripState{}, now)).code;
    const auto i = std::get<wtec::RunningValues>(ask(ascii_face, wtec::ReadRunning{}, now));
    return {sim::wtec_init_state_register(g), sim::wtec_grip_state_register(d),
            sim::wtec_percent_of(i.position, stroke)};
}

}  // namespace

TEST_CASE("wtec: the same scenario through the RTU face and the ASCII face") {
    SimClock clock;
    sim::WtecRtuModel rtu_face(1, stroke);
    sim::WtecAsciiModel ascii_face(1, stroke);
    const auto compare = [&](const char* step, bool raw_position_too) {
        INFO(step);
        const View from_rtu = rtu_view(rtu_face, clock.now());
        const View from_ascii = ascii_view(ascii_face, clock.now());
        CHECK(from_rtu == from_ascii);
        if (raw_position_too) {
            CHECK(rtu_face.gripper().position() ==
                  std::get<wtec::RunningValues>(ask(ascii_face, wtec::ReadRunning{}, clock.now())).position);
        }
    };
    const auto both_for = [&](const char* step, long long total_ms, long long every_ms) {
        for (long long t = 0; t <= total_ms; t += every_ms) {
            compare(step, true);
            clock.advance_ms(every_ms);
        }
    };

    compare("power-up", true);
    CHECK(rtu_view(rtu_face, clock.now()) == View{0, 11, 0});

    // Initialize: 0x0100 = 1 / G.
    REQUIRE(write_registers(rtu_face, 1, 0x0100, {1}, clock.now(), true) == "06 01 00 00 01");
    (void)ask(ascii_face, wtec::Home{}, clock.now());
    both_for("homing", 400, 50);
    CHECK(rtu_view(rtu_face, clock.now()) == View{1, 1, 0});

    // Speed 50 %: 0x0104 / the N speed byte through n. Force 80 %: 0x0103 / C.
    REQUIRE(write_registers(rtu_face, 1, 0x0104, {50}, clock.now(), true) == "06 01 04 00 32");
    auto params = std::get<wtec::GripperParams>(ask(ascii_face, wtec::ReadGripper{}, clock.now()));
    params.speed = 128;  // 50 % of 0xFF, rounded
    (void)ask(ascii_face, wtec::WriteGripper{params}, clock.now());
    // Both set the one grip current, the N max current: 80 % of R's max 0x3F = 50.
    REQUIRE(write_registers(rtu_face, 1, 0x0103, {80}, clock.now(), true) == "06 01 03 00 50");
    (void)ask(ascii_face, wtec::SetPeakCurrent{50}, clock.now());
    CHECK(rtu_face.gripper().grip_current() == 50);
    CHECK(std::get<wtec::GripperParams>(ask(ascii_face, wtec::ReadGripper{}, clock.now())).max_current == 50);
    CHECK(read_registers(rtu_face, 1, 0x03, 0x0103, 1, clock.now()).at(0) == ascii_face.gripper().force_percent());
    CHECK(read_registers(rtu_face, 1, 0x03, 0x0104, 1, clock.now()).at(0) ==
          ascii_face.gripper().speed_percent());

    // Position 50 %: 0x0105 = 50 / D 10000.
    REQUIRE(write_registers(rtu_face, 1, 0x0105, {50}, clock.now(), true) == "06 01 05 00 32");
    (void)ask(ascii_face, wtec::SetTarget{10000}, clock.now());
    both_for("move to 50 %", 700, 70);
    CHECK(rtu_view(rtu_face, clock.now()) == View{1, 1, 50});

    // An object 30 % wide; close fully: 0x0105 = 100 / E1.
    REQUIRE(rtu_face.control("object 30", clock.now()).empty());
    REQUIRE(ascii_face.control("object 30", clock.now()).empty());
    REQUIRE(write_registers(rtu_face, 1, 0x0105, {100}, clock.now(), true) == "06 01 05 00 64");
    (void)ask(ascii_face, wtec::GripperAction{wtec::GripAction::grip}, clock.now());
    both_for("grip the object", 400, 40);
    CHECK(rtu_view(rtu_face, clock.now()) == View{1, 2, 70});

    // E-stop: 0x0102 = 1 / the e-stop of the physical gripper.
    REQUIRE(write_registers(rtu_face, 1, 0x0102, {1}, clock.now(), true) == "06 01 02 00 01");
    REQUIRE(ascii_face.control("estop", clock.now()).empty());
    compare("e-stop", true);
    CHECK(rtu_view(rtu_face, clock.now()) == View{1, 11, 70});

    // Initialize again and open fully: 0x0105 = 0 / E2. The ASCII face presses the stop
    // (-3 counts, state 05); in the register view both read position 0 %, grip state 1.
    REQUIRE(rtu_face.control("object none", clock.now()).empty());
    REQUIRE(ascii_face.control("object none", clock.now()).empty());
    REQUIRE(write_registers(rtu_face, 1, 0x0100, {1}, clock.now(), true) == "06 01 00 00 01");
    (void)ask(ascii_face, wtec::Home{}, clock.now());
    clock.advance_s(1);
    REQUIRE(write_registers(rtu_face, 1, 0x0105, {0}, clock.now(), true) == "06 01 05 00 00");
    (void)ask(ascii_face, wtec::GripperAction{wtec::GripAction::release}, clock.now());
    clock.advance_s(2);
    compare("released", false);
    CHECK(rtu_view(rtu_face, clock.now()) == View{1, 1, 0});
}

}  // namespace fieldbridge::test
