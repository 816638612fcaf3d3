// WTEC-485 in ASCII mode: every example of the manual (seed 003 part 1) and behaviour.
#include <doctest/doctest.h>

#include "models/wtec_ascii_model.hpp"
#include "protocol/wtec_ascii_commands.hpp"
#include "sim_test_support.hpp"

namespace fieldbridge::test {
namespace {

namespace wtec = protocol::wtec;

/// The request body ('>' ... CRC) for @p command to @p address.
std::string body(std::uint8_t address, const wtec::Command& command) {
    return wtec::encode_frame_body(wtec::encode_command(address, command));
}

/// The running values of `I`, decoded.
wtec::RunningValues running(sim::WtecAsciiModel& device, Clock::time_point now) {
    const auto reply = device.on_frame(ascii(body(device.address(), wtec::ReadRunning{})), now);
    REQUIRE(reply.has_value());
    const auto frame = wtec::scan_frame(*reply);
    REQUIRE(frame.complete());
    const auto decoded = wtec::decode_reply(device.address(), wtec::ReadRunning{}, frame.value);
    REQUIRE(decoded.complete());
    return std::get<wtec::RunningValues>(decoded.value);
}

std::uint8_t state(sim::WtecAsciiModel& device, const wtec::Command& query, Clock::time_point now) {
    const auto reply = device.on_frame(ascii(body(device.address(), query)), now);
    REQUIRE(reply.has_value());
    const auto frame = wtec::scan_frame(*reply);
    REQUIRE(frame.complete());
    const auto decoded = wtec::decode_reply(device.address(), query, frame.value);
    REQUIRE(decoded.complete());
    return std::get<wtec::StateCode>(decoded.value).code;
}

}  // namespace

TEST_CASE("wtec-ascii: every example of the manual, byte for byte") {
    SimClock clock;
    sim::WtecAsciiModel wtec01(1, 20000);
    const auto ex = [&](std::string_view request) { return exchange_ascii(wtec01, request, clock.now()); };

    CHECK(ex(">01A63D8") == ">01ACstep [A]1.623921");
    CHECK(ex(">01a14EBB") == ">01aBBD9");
    CHECK(ex(">01B6298") == ">01BFC0000753000030D40000003E8411000000C800989680621D");
    CHECK(ex(">01bFC0000753000030D40000003E8411000000C800989680B00E") == ">01bBA99");
    CHECK(ex(">01C3CE8EE") == ">01CA259");
    CHECK(ex(">01P6F18") == ">01P008000000090C9EF");
    CHECK(ex(">01p008000000090A990") == ">01pB719");
    CHECK(ex(">01RAE99") == ">01R0007A120004C4B403F0030227100000010406C70");
    CHECK(ex(">01r0007A120004C4B403F003022710000001040AFC9") == ">01r7698");
    CHECK(ex(">01WAD59") == ">01W5CFF00000000000000000000000000D508");
    CHECK(ex(">01w5CFF000000000000000000000000000709") == ">01w7558");
    CHECK(ex(">01U6CD8") == ">01U6CD8");
    CHECK(ex(">01n00005C443FFF0A119FE") == ">01nBF99");
    CHECK(ex(">01N6798") == ">01N00005C443FFF0A1C1E7");
    // E before homing: answered with the request itself, nothing moves.
    CHECK(ex(">01E14EA0") == ">01E14EA0");
    CHECK(ex(">01G6158") == ">01G6158");
    CHECK(state(wtec01, wtec::QueryHoming{}, clock.now()) == wtec::homing_state::homing);
    clock.advance_s(1);
    CHECK(ex(">01gB959") == ">01g01362E");
    CHECK(ex(">01dB819") == ">01d0136DE");
    CHECK(ex(">01E14EA0") == ">01EA0D9");
    clock.advance_s(1);
    CHECK(state(wtec01, wtec::QueryGripState{}, clock.now()) == wtec::grip_state::closed_without_object);
    // Release to the limit: the I example (position -3, current 03, enabled, state 05).
    REQUIRE(ex(body(1, wtec::GripperAction{wtec::GripAction::release})) == ">01EA0D9");
    clock.advance_s(1);
    CHECK(ex(">01IA5D9") == ">01IFFFFFFFD031054786");
    // D: the printed request has 9 data digits and gets no reply; 8 digits are answered.
    CHECK(ex(">01D0001FFFFFDF01").empty());
    CHECK(ex(body(1, wtec::SetTarget{0x0001FFFF})) == ">01D6018");
    // Z: the printed CRC does not verify, so no reply; a valid Z is acknowledged.
    CHECK(ex(">01Z4358").empty());
    CHECK(ex(body(1, wtec::CalibrateEncoder{})) ==
          wtec::encode_frame_body(wtec::encode_reply(1, wtec::CalibrateEncoder{}, wtec::Ack{})));
    // i: the reply comes from the new address.
    CHECK(ex(">01i0A114E") == ">0AiBDFD");
    CHECK(wtec01.address() == 0x0A);
    CHECK(ex(">01A63D8").empty());
}

TEST_CASE("wtec-ascii: '$' to 00 is answered by every device on the bus") {
    SimClock clock;
    sim::WtecAsciiModel wtec01(1, 20000);
    sim::WtecAsciiModel wtec02(2, 20000);
    CHECK(exchange_ascii(wtec01, ">00$D819", clock.now()) == ">01$01E2DF");
    CHECK(exchange_ascii(wtec02, ">00$D819", clock.now()) == ">02$02A79F");
}

TEST_CASE("wtec-ascii: D moves in position mode, E grips and releases, a releases the motor") {
    SimClock clock;
    sim::WtecAsciiModel wtec(1, 20000);
    // D before homing only stores the target.
    REQUIRE(exchange_ascii(wtec, body(1, wtec::SetTarget{5000}), clock.now()) == ">01D6018");
    CHECK(state(wtec, wtec::QueryGripState{}, clock.now()) == wtec::grip_state::motor_released);
    CHECK(running(wtec, clock.now()) == wtec::RunningValues{0, 0, false, wtec::grip_state::motor_released});
    REQUIRE(!exchange_ascii(wtec, body(1, wtec::Home{}), clock.now()).empty());
    clock.advance_s(1);

    // Speed byte 0xFF: 40000 counts/s for a 20000-count stroke.
    REQUIRE(!exchange_ascii(wtec, body(1, wtec::SetTarget{10000}), clock.now()).empty());
    clock.advance_ms(100);
    CHECK(running(wtec, clock.now()).position == 4000);
    CHECK(state(wtec, wtec::QueryGripState{}, clock.now()) == wtec::grip_state::moving);
    clock.advance_ms(200);
    CHECK(running(wtec, clock.now()) == wtec::RunningValues{10000, 3, true, wtec::grip_state::reached});

    // Grip an object 25 % wide: contact at 15000 counts, holding at the grip current
    // (the N max current, which C sets).
    REQUIRE(wtec.control("object 25", clock.now()).empty());
    REQUIRE(!exchange_ascii(wtec, body(1, wtec::SetPeakCurrent{0x3C}), clock.now()).empty());
    CHECK(wtec.gripper().gripper_params().max_current == 0x3C);  // what `N` reads
    REQUIRE(exchange_ascii(wtec, body(1, wtec::GripperAction{wtec::GripAction::grip}), clock.now()) == ">01EA0D9");
    clock.advance_ms(50);
    CHECK(running(wtec, clock.now()).current == 0x3C);  // closing at the grip current
    clock.advance_s(1);
    CHECK(running(wtec, clock.now()) == wtec::RunningValues{15000, 0x3C, true, wtec::grip_state::gripped});

    // Toggle: the last action was a grip, so E3 releases (at the W release current).
    REQUIRE(exchange_ascii(wtec, body(1, wtec::GripperAction{wtec::GripAction::toggle}), clock.now()) == ">01EA0D9");
    clock.advance_ms(10);
    CHECK(running(wtec, clock.now()).current == 0x5C);
    clock.advance_s(1);
    CHECK(running(wtec, clock.now()) == wtec::RunningValues{-3, 3, true, wtec::grip_state::released_to_limit});

    // a0 releases the motor: E is echoed, nothing moves; a1 enables it again.
    REQUIRE(exchange_ascii(wtec, body(1, wtec::SetMotorEnable{false}), clock.now()) ==
            wtec::encode_frame_body(wtec::encode_reply(1, wtec::SetMotorEnable{false}, wtec::Ack{})));
    CHECK(running(wtec, clock.now()) == wtec::RunningValues{-3, 0, false, wtec::grip_state::motor_released});
    CHECK(exchange_ascii(wtec, ">01E14EA0", clock.now()) == ">01E14EA0");
    REQUIRE(!exchange_ascii(wtec, ">01a14EBB", clock.now()).empty());
    CHECK(state(wtec, wtec::QueryGripState{}, clock.now()) == wtec::grip_state::released_to_limit);

    // An e-stop (Modbus face) keeps the motor released: a1 cannot enable it, G can.
    REQUIRE(wtec.control("estop", clock.now()).empty());
    REQUIRE(!exchange_ascii(wtec, ">01a14EBB", clock.now()).empty());
    CHECK(!running(wtec, clock.now()).enabled);
    REQUIRE(!exchange_ascii(wtec, ">01G6158", clock.now()).empty());
    clock.advance_s(1);
    CHECK(running(wtec, clock.now()).enabled);

    // Z loses the homing reference.
    REQUIRE(!exchange_ascii(wtec, body(1, wtec::CalibrateEncoder{}), clock.now()).empty());
    CHECK(state(wtec, wtec::QueryHoming{}, clock.now()) == wtec::homing_state::not_homed);
}

TEST_CASE("wtec-ascii: after a0 the motor stays released until a1; D is echoed meanwhile") {
    SimClock clock;
    sim::WtecAsciiModel wtec(1, 20000);
    REQUIRE(!exchange_ascii(wtec, body(1, wtec::Home{}), clock.now()).empty());
    clock.advance_s(1);
    REQUIRE(!exchange_ascii(wtec, body(1, wtec::SetTarget{10000}), clock.now()).empty());
    clock.advance_s(1);
    REQUIRE(running(wtec, clock.now()) == wtec::RunningValues{10000, 3, true, wtec::grip_state::reached});
    // a0 (the view's e-stop): released. G alone does not enable it: nothing moves.
    REQUIRE(!exchange_ascii(wtec, body(1, wtec::SetMotorEnable{false}), clock.now()).empty());
    CHECK(exchange_ascii(wtec, ">01G6158", clock.now()) == ">01G6158");
    clock.advance_s(1);
    CHECK(running(wtec, clock.now()) == wtec::RunningValues{10000, 0, false, wtec::grip_state::motor_released});
    // D is not executed: the request comes back as it was sent, the target unchanged.
    const std::string d = body(1, wtec::SetTarget{6000});
    CHECK(exchange_ascii(wtec, d, clock.now()) == d);
    CHECK(wtec.gripper().gripper_params().target == 10000);
    // a1 then G: enabled and homed again, and D moves.
    REQUIRE(!exchange_ascii(wtec, body(1, wtec::SetMotorEnable{true}), clock.now()).empty());
    REQUIRE(!exchange_ascii(wtec, body(1, wtec::Home{}), clock.now()).empty());
    clock.advance_s(2);
    CHECK(state(wtec, wtec::QueryHoming{}, clock.now()) == wtec::homing_state::homed);
    CHECK(exchange_ascii(wtec, d, clock.now()) == ">01D6018");
    clock.advance_s(1);
    CHECK(running(wtec, clock.now()) == wtec::RunningValues{6000, 3, true, wtec::grip_state::reached});
}

TEST_CASE("wtec-ascii: addressing, broadcast and undecodable frames") {
    SimClock clock;
    sim::WtecAsciiModel wtec(1, 20000);
    CHECK(exchange_ascii(wtec, body(2, wtec::ReadVersion{}), clock.now()).empty());
    // G to 00 homes every device without a reply.
    CHECK(exchange_ascii(wtec, body(0, wtec::Home{}), clock.now()).empty());
    clock.advance_s(1);
    CHECK(state(wtec, wtec::QueryHoming{}, clock.now()) == wtec::homing_state::homed);
    // A with data, an unknown letter, lower-case hex, no CR LF: no reply.
    const std::string bad_a = wtec::encode_frame_body(wtec::AsciiFrame{1, 'A', "00"});
    CHECK(exchange_ascii(wtec, bad_a, clock.now()).empty());
    CHECK(exchange_ascii(wtec, wtec::encode_frame_body(wtec::AsciiFrame{1, 'Q', ""}), clock.now()).empty());
    CHECK(exchange_ascii(wtec, ">01a14ebb", clock.now()).empty());
    const std::string version = body(1, wtec::ReadVersion{});
    CHECK(!wtec.on_frame(protocol::Bytes(version.begin(), version.end()), clock.now()).has_value());
    CHECK_THROWS_AS(sim::WtecAsciiModel(0, 20000), std::invalid_argument);
    CHECK_THROWS_AS(sim::WtecAsciiModel(254, 20000), std::invalid_argument);
}

}  // namespace fieldbridge::test
