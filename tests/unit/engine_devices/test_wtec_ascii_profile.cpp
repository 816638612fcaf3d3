// The WTEC ASCII uniform register view (spec §5; docs/registers.md), both ways.
#include <doctest/doctest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "engine/profiles/profile_factory.hpp"
#include "engine/profiles/wtec_ascii_profile.hpp"
#include "engine/profiles/wtec_rtu_profile.hpp"
#include "support.hpp"

namespace {

using namespace fbt;
using fe::Table;
using fp::ExceptionCode;

constexpr std::uint32_t stroke = 10000;

fe::ProfileOptions ascii_options(bool allow_protected = false) {
    fe::ProfileOptions o;
    o.address = fieldbridge::core::BusAddress{7};
    o.wtec_stroke = stroke;
    o.allow_protected = allow_protected;
    return o;
}

fw::DriverParams driver(std::uint8_t max_current) {
    // Seed 003 command 18's example, with the max current under test.
    return fw::DriverParams{0x0007A120, 0x004C4B40, max_current, 0, 0x03, 0x02, 0x2710, 0x10, 0};
}
fw::GripperParams gripper(std::uint32_t target, std::uint8_t current, std::uint8_t speed) {
    return fw::GripperParams{target, current, speed, 0x0A, 1};
}
fw::HomingParams homing(std::uint8_t mode) {
    // Seed 003 command 4's example.
    return fw::HomingParams{mode, 0x7530, 0x30D40, 0x3E8, 0x41, 1, 0xC8, 0x989680};
}

struct View {
    explicit View(bool allow_protected = false) : profile(ascii_options(allow_protected)) {}
    fe::WtecAsciiProfile profile;
    fe::RegisterImage image;

    fe::ApplyResult feed(fw::Command command, fw::Reply reply) {
        return profile.apply(fe::AsciiPayload{std::move(command)}, ascii(std::move(reply)), image, t0());
    }
    std::optional<ExceptionCode> check(const fp::Request& r) const { return profile.validate(r, image); }
    std::string letters(const fp::Request& r) const {
        std::string out;
        for (const auto& p : profile.to_line(r, image)) out.push_back(fw::letter_of(command_of(p)));
        return out;
    }
    /// A whole northbound exchange: validate, to_line, apply every reply (up to a
    /// refusal), respond.
    fp::Response exchange(const fp::Request& r, const std::vector<fw::Reply>& answers) {
        if (const auto bad = profile.validate(r, image)) return fp::ExceptionResponse{fp::function_of(r), *bad};
        const auto payloads = profile.to_line(r, image);
        REQUIRE(payloads.size() == answers.size());
        std::vector<fe::Reply> replies;
        for (std::size_t i = 0; i < payloads.size(); ++i) {
            replies.push_back(ascii(answers[i]));
            const auto status = profile.apply(payloads[i], replies.back(), image, t0()).status;
            if (std::holds_alternative<fw::NotExecuted>(answers[i])) {
                // A refusal ends the sequence, as in the agent.
                CHECK(status == fe::ApplyStatus::device_exception);
                break;
            }
            CHECK(status == fe::ApplyStatus::applied);
        }
        return profile.respond(r, replies, image);
    }
    /// The state every poll fills: homed, gripped at 48 %, target 50 %, force 80 %, speed 100 %.
    void polled() {
        (void)feed(fw::ReadRunning{}, fw::RunningValues{4800, 10, true, fw::grip_state::gripped});
        (void)feed(fw::QueryHoming{}, fw::StateCode{fw::homing_state::homed});
        (void)feed(fw::ReadDriver{}, driver(100));
        (void)feed(fw::ReadGripper{}, gripper(5000, 80, 0xFF));
        (void)feed(fw::ReadHoming{}, homing(0xFC));
    }
};

}  // namespace

TEST_CASE("wtec-ascii: percentages and raw values round-trip") {
    CHECK(fe::wtec_percent_to_raw(50, stroke) == 5000);
    CHECK(fe::wtec_percent_to_raw(1, 255) == 3);
    CHECK(fe::wtec_percent_to_raw(100, 255) == 255);
    CHECK(fe::wtec_percent_to_raw(150, 255) == 255);  // clamped
    for (const std::uint32_t full : {100U, 255U, 10000U, 23620U}) {
        for (std::uint16_t p = 0; p <= 100; ++p) {
            CHECK(fe::wtec_raw_to_percent(fe::wtec_percent_to_raw(p, full), full) == p);
        }
    }
    // Below 100 steps several percentages share a raw value: the smallest comes back.
    for (std::uint16_t p = 20; p <= 100; ++p) {
        const auto raw = fe::wtec_percent_to_raw(p, 63);
        const auto back = fe::wtec_raw_to_percent(raw, 63);
        CHECK(back <= p);
        CHECK(fe::wtec_percent_to_raw(back, 63) == raw);
    }
    CHECK(fe::wtec_raw_to_percent(-3, stroke) == 0);
    CHECK(fe::wtec_raw_to_percent(stroke + 5, stroke) == 100);
    CHECK(fe::wtec_raw_to_percent(7, 0) == 0);
    CHECK(fe::wtec_raw_to_percent(4, 255) == 2);  // 4 is no percentage's value: nearest
}

TEST_CASE("wtec-ascii: force is the grip current over R's max current, rounded") {
    // docs/registers.md: force % = round(N max x 100 / R max), capped at 100; a force
    // write sends C = round(f x R max / 100).
    CHECK(fe::wtec_force_percent(0x3F, 0x3F) == 100);
    CHECK(fe::wtec_force_percent(0x3F, 0x78) == 53);  // 52.5, rounded up
    CHECK(fe::wtec_force_percent(50, 0x3F) == 79);
    CHECK(fe::wtec_force_percent(0x3F, 0x3E) == 100);  // above R's max: capped
    CHECK(fe::wtec_force_percent(0, 0x3F) == 0);
    CHECK(fe::wtec_force_percent(10, 0) == 0);
    CHECK(fe::wtec_force_current(80, 0x3F) == 50);
    CHECK(fe::wtec_force_current(50, 0x3F) == 32);  // 31.5, rounded up
    CHECK(fe::wtec_force_current(150, 0x3F) == 0x3F);  // clamped to 100 %
    for (const std::uint32_t full : {100U, 0x78U, 0xFFU}) {
        for (std::uint16_t p = 0; p <= 100; ++p) {
            CHECK(fe::wtec_force_percent(fe::wtec_force_current(p, full), full) == p);
        }
    }
    // Below 100 steps a percentage comes back within 1.
    for (std::uint16_t p = 20; p <= 100; ++p) {
        const int back = fe::wtec_force_percent(fe::wtec_force_current(p, 0x3F), 0x3F);
        CHECK(std::abs(back - p) <= 1);
    }
}

TEST_CASE("wtec-ascii: state codes in the uniform registers") {
    CHECK(fe::wtec_uniform_grip_state(0x00) == 0);
    CHECK(fe::wtec_uniform_grip_state(0x01) == 1);
    CHECK(fe::wtec_uniform_grip_state(0x02) == 2);
    CHECK(fe::wtec_uniform_grip_state(0x05) == 1);
    CHECK(fe::wtec_uniform_grip_state(0x06) == 1);
    CHECK(fe::wtec_uniform_grip_state(0x11) == 11);
    CHECK(fe::wtec_uniform_grip_state(0x07) == 7);
    CHECK(fe::wtec_uniform_init_state(0x00) == 0);
    CHECK(fe::wtec_uniform_init_state(0x01) == 1);
    CHECK(fe::wtec_uniform_init_state(0x02) == 2);
    CHECK(fe::wtec_uniform_init_state(0x03) == 2);
    CHECK(fe::wtec_uniform_init_state(0x09) == 9);
}

TEST_CASE("wtec-ascii: options") {
    fe::ProfileOptions none;
    CHECK_THROWS_AS(fe::WtecAsciiProfile{none}, fe::ProfileError);
    none.wtec_stroke = 0;
    CHECK_THROWS_AS((void)fe::make_profile(fe::DeviceType::wtec_ascii, none), fe::ProfileError);
    const View v;
    CHECK(v.profile.bus() == fe::Bus::wtec_ascii);
    CHECK(v.profile.type() == fe::DeviceType::wtec_ascii);
    CHECK(v.profile.broadcast_address() == fieldbridge::core::BusAddress{0});
}

TEST_CASE("wtec-ascii: poll plan") {
    const View v;
    std::vector<std::string> seen;
    const fe::PollPlan plan = v.profile.poll_plan();
    for (const auto& item : plan.items()) {
        seen.push_back(std::string{fe::to_string(item.poll_class)} + " " + fw::letter_of(command_of(item.payload)) +
                       (item.motion ? " motion" : ""));
        CHECK(item.units.empty());  // nothing to split
        CHECK_FALSE(item.fills.empty());
    }
    const std::vector<std::string> expected{"fast I motion", "fast g motion", "slow N",   "slow R",
                                            "slow B",        "startup A",     "startup P", "startup W"};
    CHECK(seen == expected);
}

TEST_CASE("wtec-ascii: replies fill the uniform registers and the extension block") {
    View v;
    // Seed 003 command 12 (corrected in vectors.yaml): position -3, current 3, enabled, state 05.
    CHECK(v.feed(fw::ReadRunning{}, fw::RunningValues{-3, 3, true, 0x05}).status == fe::ApplyStatus::applied);
    CHECK(values_of(v.image, Table::input, 0x1000, 5) == std::vector<std::uint16_t>{0xFFFF, 0xFFFD, 3, 1, 5});
    CHECK(v.image.value(Table::holding, 0x0202) == 1);  // released to the limit: stopped, no object
    CHECK(v.image.value(Table::holding, 0x0204) == 0);  // before the homing point: 0
    // The gateway's own registers: the e-stop latch (0) and the configured address.
    CHECK(v.image.value(Table::holding, 0x0102) == 0);
    CHECK(v.image.value(Table::holding, 0x0303) == 7);

    (void)v.feed(fw::QueryHoming{}, fw::StateCode{0x03});
    CHECK(v.image.value(Table::holding, 0x0200) == 2);
    CHECK(v.image.value(Table::input, 0x1005) == 3);
    (void)v.feed(fw::QueryGripState{}, fw::StateCode{0x11});
    CHECK(v.image.value(Table::holding, 0x0202) == 11);
    CHECK(v.image.value(Table::input, 0x1004) == 0x11);

    // Seed 003 command 16: N = 00005C44 3F FF 0A 1. Force needs R first.
    (void)v.feed(fw::ReadGripper{}, gripper(0x5C44, 0x3F, 0xFF));
    CHECK(values_of(v.image, Table::input, 0x1006, 6) == std::vector<std::uint16_t>{0, 0x5C44, 0x3F, 0xFF, 0x0A, 1});
    CHECK(v.image.value(Table::holding, 0x0104) == 100);
    CHECK(v.image.value(Table::holding, 0x0105) == 100);  // 0x5C44 = 23620 > stroke: clamped
    CHECK_FALSE(v.image.value(Table::holding, 0x0103).has_value());
    (void)v.feed(fw::ReadDriver{}, driver(0x7E));  // 126: 63 is half of it
    CHECK(v.image.value(Table::holding, 0x0103) == 50);
    CHECK(values_of(v.image, Table::input, 0x100C, 12) ==
          std::vector<std::uint16_t>{0x0007, 0xA120, 0x004C, 0x4B40, 0x7E, 0, 3, 2, 0x2710, 0, 0x10, 0});

    (void)v.feed(fw::ReadHoming{}, homing(0xFD));
    CHECK(v.image.value(Table::holding, 0x0300) == 2);
    CHECK(values_of(v.image, Table::input, 0x1018, 13) ==
          std::vector<std::uint16_t>{0xFD, 0, 0x7530, 0x0003, 0x0D40, 0, 0x03E8, 0x41, 1, 0, 0xC8, 0x0098, 0x9680});
    (void)v.feed(fw::ReadHoming{}, homing(0xFC));
    CHECK(v.image.value(Table::holding, 0x0300) == 1);

    (void)v.feed(fw::ReadPid{}, fw::Pid{0x80, 0, 0x90});
    (void)v.feed(fw::ReadRelease{}, fw::ReleaseParams{0x5C, 0xFF});
    (void)v.feed(fw::ReadVersion{}, fw::Version{"Cstep [A]1.62"});
    CHECK(values_of(v.image, Table::input, 0x1025, 5) == std::vector<std::uint16_t>{0x80, 0, 0x90, 0x5C, 0xFF});
    CHECK(v.image.value(Table::input, 0x102A) == 0x4373);  // "Cs"
    CHECK(v.image.value(Table::input, 0x1030) == 0x3200);  // "2" + padding
    CHECK(field<std::string>(v.profile.decode_state(v.image), "firmware") == "Cstep [A]1.62");

    // A reply that does not answer the command changes nothing.
    CHECK(v.feed(fw::ReadGripper{}, fw::Ack{}).status == fe::ApplyStatus::not_applicable);
    CHECK(v.profile.apply(fe::ModbusPayload{read_holding(0x0200, 1)}, registers(0x03, {1}), v.image, t0()).status ==
          fe::ApplyStatus::not_applicable);
}

TEST_CASE("wtec-ascii: an E or D the gripper echoes back was not executed: 0x04, never 0x0B") {
    View v;
    v.polled();
    const auto refused = v.feed(fw::GripperAction{fw::GripAction::grip}, fw::NotExecuted{});
    CHECK(refused.status == fe::ApplyStatus::device_exception);
    CHECK(refused.exception == ExceptionCode::server_device_failure);
    REQUIRE(refused.notice.has_value());
    CHECK(refused.notice->text.find("did not execute `E`") != std::string::npos);
    // 0x0105 = 30 -> D 3000, echoed: the view keeps its old target.
    CHECK(v.exchange(write_single(0x0105, 30), {fw::NotExecuted{}}) ==
          fp::Response{fp::ExceptionResponse{0x06, ExceptionCode::server_device_failure}});
    CHECK(v.image.value(Table::holding, 0x0105) == 50);
    const auto d = v.feed(fw::SetTarget{3000}, fw::NotExecuted{});
    REQUIRE(d.notice.has_value());
    CHECK(d.notice->text.find("did not execute `D`") != std::string::npos);
    CHECK(d.notice->text.find("initialise it") != std::string::npos);
    // In an FC16 sequence the refusal ends it with 0x04 too.
    CHECK(v.exchange(write_multiple(0x0104, {50, 30}), {fw::Ack{}, fw::NotExecuted{}}) ==
          fp::Response{fp::ExceptionResponse{0x10, ExceptionCode::server_device_failure}});
}

TEST_CASE("wtec-ascii: 0x0105 shows the target last sent, whatever N's target parameter says (issue 24 item 5)") {
    View v;
    v.polled();  // N's target 5000 of 10000: 50 %
    CHECK(v.image.value(Table::holding, 0x0105) == 50);
    // e-stop, initialise, move to 30 %: D 3000 acknowledged.
    CHECK(v.exchange(write_single(0x0102, 1), {fw::Ack{}}) == fp::Response{fp::WriteSingleResponse{0x06, 0x0102, 1}});
    CHECK(v.exchange(write_single(0x0100, 1), {fw::Ack{}, fw::Ack{}}) ==
          fp::Response{fp::WriteSingleResponse{0x06, 0x0100, 1}});
    CHECK(v.exchange(write_single(0x0105, 30), {fw::Ack{}}) == fp::Response{fp::WriteSingleResponse{0x06, 0x0105, 30}});
    CHECK(v.image.value(Table::holding, 0x0105) == 30);
    // D moved the jaws without changing N's target (the manual's example device keeps
    // 0x5C44 there): the next N poll leaves 0x0105 at what was sent.
    (void)v.feed(fw::ReadGripper{}, gripper(0x5C44, 80, 0xFF));
    CHECK(v.image.value(Table::holding, 0x0105) == 30);
    CHECK(values_of(v.image, Table::input, 0x1006, 2) == std::vector<std::uint16_t>{0, 0x5C44});
    // A speed write sends `n` with N's target as the device has it, not D's.
    const auto speed = v.profile.to_line(write_single(0x0104, 50), v.image);
    REQUIRE(speed.size() == 1);
    CHECK(std::get<fw::WriteGripper>(command_of(speed[0])).params.target == 0x5C44);
    CHECK(v.exchange(write_single(0x0104, 50), {fw::Ack{}}) == fp::Response{fp::WriteSingleResponse{0x06, 0x0104, 50}});
    CHECK(v.image.value(Table::holding, 0x0105) == 30);
    // A D the gripper did not execute leaves it as it was.
    CHECK(v.exchange(write_single(0x0105, 70), {fw::NotExecuted{}}) ==
          fp::Response{fp::ExceptionResponse{0x06, ExceptionCode::server_device_failure}});
    (void)v.feed(fw::ReadGripper{}, gripper(0x5C44, 80, 0xFF));
    CHECK(v.image.value(Table::holding, 0x0105) == 30);
}

TEST_CASE("wtec-ascii: on-demand reads send the commands that fill what is asked") {
    const View v;
    CHECK(v.letters(read_holding(0x0200, 1)) == "g");
    CHECK(v.letters(read_holding(0x0202, 1)) == "d");
    CHECK(v.letters(read_holding(0x0204, 1)) == "I");
    CHECK(v.letters(read_holding(0x0103, 1)) == "NR");
    CHECK(v.letters(read_holding(0x0104, 2)) == "N");
    CHECK(v.letters(read_holding(0x0300, 1)) == "B");
    CHECK(v.letters(read_holding(0x0102, 1)) == "I");  // the latch: just check the device is there
    CHECK(v.letters(read_holding(0x0303, 1)) == "I");
    CHECK(v.letters(read_input(0x1000, 0x32)) == "IdgNRBPWA");
    CHECK(v.letters(read_input(0x1025, 3)) == "P");
}

TEST_CASE("wtec-ascii: validation") {
    View v;
    CHECK(v.check(read_bits(fp::fc::read_coils, 0, 1)) == ExceptionCode::illegal_function);
    CHECK(v.check(fp::ReadExceptionStatusRequest{}) == ExceptionCode::illegal_function);
    CHECK(v.check(read_holding(0x0100, 1)) == ExceptionCode::illegal_data_address);  // write-only, as in RTU
    CHECK(v.check(read_holding(0x0302, 1)) == ExceptionCode::illegal_data_address);  // no ASCII command reads it
    CHECK(v.check(read_holding(0x0200, 3)) == ExceptionCode::illegal_data_address);
    CHECK(v.check(read_input(0x0200, 1)) == ExceptionCode::illegal_data_address);
    CHECK(v.check(read_input(0x1000, 0x33)) == ExceptionCode::illegal_data_address);  // past 0x1031
    CHECK(v.check(write_single(0x1000, 1)) == ExceptionCode::illegal_data_address);
    CHECK_FALSE(v.check(read_input(0x1000, 0x32)));
    CHECK(v.check(write_single(0x0103, 10)) == ExceptionCode::illegal_data_value);
    CHECK(v.check(write_single(0x0302, 1)) == ExceptionCode::illegal_function);  // protected
    CHECK(v.check(write_single(0x0303, 3)) == ExceptionCode::illegal_function);
    // Translations that need device data not read yet: 0x0B.
    CHECK(v.check(write_single(0x0103, 80)) == ExceptionCode::gateway_target_failed);
    CHECK(v.check(write_single(0x0104, 50)) == ExceptionCode::gateway_target_failed);
    CHECK(v.check(write_single(0x0300, 2)) == ExceptionCode::gateway_target_failed);
    CHECK_FALSE(v.check(write_single(0x0105, 50)));  // needs only the stroke
    v.polled();
    CHECK_FALSE(v.check(write_single(0x0103, 80)));
    CHECK_FALSE(v.check(write_single(0x0104, 50)));
    CHECK_FALSE(v.check(write_single(0x0300, 2)));
    // R max current 0 cannot scale a force.
    (void)v.feed(fw::ReadDriver{}, driver(0));
    CHECK(v.check(write_single(0x0103, 80)) == ExceptionCode::gateway_target_failed);

    const View allowed{true};
    CHECK_FALSE(allowed.check(write_single(0x0302, 1)));
    CHECK(allowed.check(write_single(0x0302, 0)) == ExceptionCode::illegal_data_value);
    CHECK(allowed.check(write_single(0x0303, 254)) == ExceptionCode::illegal_data_value);
}

TEST_CASE("wtec-ascii: writes become ASCII commands") {
    View v{true};
    v.polled();
    const auto one = [&v](const fp::Request& r) {
        const auto out = v.profile.to_line(r, v.image);
        REQUIRE(out.size() == 1);
        return command_of(out[0]);
    };
    // Initialise: a1 (enable the motor, released after an e-stop), then G (home).
    CHECK(v.letters(write_single(0x0100, 1)) == "aG");
    const auto init = v.profile.to_line(write_single(0x0100, 1), v.image);
    REQUIRE(init.size() == 2);
    CHECK(command_of(init[0]) == fw::Command{fw::SetMotorEnable{true}});
    CHECK(command_of(init[1]) == fw::Command{fw::Home{}});
    CHECK(one(write_single(0x0102, 1)) == fw::Command{fw::SetMotorEnable{false}});
    CHECK(one(write_single(0x0103, 80)) == fw::Command{fw::SetPeakCurrent{80}});  // R max 100
    CHECK(one(write_single(0x0104, 50)) == fw::Command{fw::WriteGripper{gripper(5000, 80, 128)}});
    CHECK(one(write_single(0x0105, 25)) == fw::Command{fw::SetTarget{2500}});
    CHECK(one(write_single(0x0300, 2)) == fw::Command{fw::WriteHoming{homing(0xFD)}});
    CHECK(one(write_single(0x0300, 1)) == fw::Command{fw::WriteHoming{homing(0xFC)}});
    CHECK(one(write_single(0x0302, 1)) == fw::Command{fw::SaveAll{}});
    CHECK(one(write_single(0x0303, 10)) == fw::Command{fw::SetAddress{10}});

    // FC16 over force, speed and position: C, then n with C's new current, then D.
    const auto seq = v.profile.to_line(write_multiple(0x0103, {60, 100, 40}), v.image);
    REQUIRE(seq.size() == 3);
    CHECK(command_of(seq[0]) == fw::Command{fw::SetPeakCurrent{60}});
    CHECK(command_of(seq[1]) == fw::Command{fw::WriteGripper{gripper(5000, 60, 0xFF)}});
    CHECK(command_of(seq[2]) == fw::Command{fw::SetTarget{4000}});

    // With R's max current 63 (seed 003's example), 50 % is round(31.5) = 32 and
    // 80 % is round(50.4) = 50.
    (void)v.feed(fw::ReadDriver{}, driver(63));
    CHECK(one(write_single(0x0103, 50)) == fw::Command{fw::SetPeakCurrent{32}});
    CHECK(one(write_single(0x0103, 80)) == fw::Command{fw::SetPeakCurrent{50}});
}

TEST_CASE("wtec-ascii: acknowledged writes update the view; the e-stop latch") {
    View v;
    v.polled();
    CHECK(v.exchange(write_single(0x0105, 25), {fw::Ack{}}) == fp::Response{fp::WriteSingleResponse{0x06, 0x0105, 25}});
    CHECK(v.image.value(Table::holding, 0x0105) == 25);
    // N's target parameter (5000, polled) stays: `D` does not change it.
    CHECK(values_of(v.image, Table::input, 0x1006, 2) == std::vector<std::uint16_t>{0, 5000});

    CHECK(v.exchange(write_multiple(0x0103, {60, 1}), {fw::Ack{}, fw::Ack{}}) ==
          fp::Response{fp::WriteMultipleResponse{0x10, 0x0103, 2}});
    CHECK(v.image.value(Table::holding, 0x0103) == 60);
    CHECK(v.image.value(Table::holding, 0x0104) == 1);
    CHECK(v.image.value(Table::input, 0x1008) == 60);
    CHECK(v.image.value(Table::input, 0x1009) == 3);

    CHECK(v.exchange(write_single(0x0300, 2), {fw::Ack{}}) == fp::Response{fp::WriteSingleResponse{0x06, 0x0300, 2}});
    CHECK(v.image.value(Table::holding, 0x0300) == 2);
    CHECK(v.image.value(Table::input, 0x1018) == 0xFD);

    // E-stop: a0 acknowledged latches 0x0102 = 1 (an alarm) until G is acknowledged.
    CHECK(v.profile.classify(write_single(0x0102, 1)).urgent_stop);
    (void)v.exchange(write_single(0x0102, 1), {fw::Ack{}});
    CHECK(v.image.value(Table::holding, 0x0102) == 1);
    (void)v.feed(fw::ReadRunning{}, fw::RunningValues{4800, 0, false, fw::grip_state::motor_released});
    CHECK(v.image.value(Table::holding, 0x0102) == 1);  // a poll does not clear it
    auto alarms = v.profile.alarms(v.image);
    REQUIRE(alarms.size() == 1);
    CHECK(alarms[0].code == "emergency_stop");
    CHECK(v.exchange(read_holding(0x0102, 1), {fw::RunningValues{4800, 0, false, 0x11}}) ==
          fp::Response{fp::ReadRegistersResponse{0x03, {1}}});
    // Initialise: a1 acknowledged keeps the latch; the acknowledged G clears it.
    CHECK(v.feed(fw::SetMotorEnable{true}, fw::Ack{}).status == fe::ApplyStatus::applied);
    CHECK(v.image.value(Table::holding, 0x0102) == 1);
    CHECK(v.exchange(write_single(0x0100, 1), {fw::Ack{}, fw::Ack{}}) ==
          fp::Response{fp::WriteSingleResponse{0x06, 0x0100, 1}});
    CHECK(v.image.value(Table::holding, 0x0102) == 0);
    CHECK(v.profile.alarms(v.image).empty());

    // A missing or wrong acknowledgement: 0x0B.
    CHECK(v.profile.respond(write_single(0x0105, 10), {}, v.image) ==
          fp::Response{fp::ExceptionResponse{0x06, ExceptionCode::gateway_target_failed}});
    const std::vector<fe::Reply> wrong{ascii(fw::StateCode{1})};
    CHECK(v.profile.respond(write_single(0x0105, 10), wrong, v.image) ==
          fp::Response{fp::ExceptionResponse{0x06, ExceptionCode::gateway_target_failed}});
}

TEST_CASE("wtec-ascii: reads answered from the image after the commands") {
    View v;
    const auto r = v.exchange(read_input(0x1000, 4), {fw::RunningValues{-3, 3, true, 0x05}});
    CHECK(r == fp::Response{fp::ReadRegistersResponse{0x04, {0xFFFF, 0xFFFD, 3, 1}}});
    const auto force = v.exchange(read_holding(0x0103, 3), {gripper(5000, 80, 0xFF), driver(100)});
    CHECK(force == fp::Response{fp::ReadRegistersResponse{0x03, {80, 100, 50}}});
    const auto state = v.profile.decode_state(v.image);
    CHECK(field<std::int64_t>(state, "position_counts") == -3);
    CHECK(field<bool>(state, "enabled"));
    CHECK(field<std::int64_t>(state, "grip_code") == 5);
    CHECK(field<std::int64_t>(state, "force_pct") == 80);
    CHECK(v.profile.in_motion(v.image) == false);
    (void)v.feed(fw::ReadRunning{}, fw::RunningValues{100, 3, true, fw::grip_state::moving});
    CHECK(v.profile.in_motion(v.image));
    (void)v.feed(fw::ReadRunning{}, fw::RunningValues{100, 3, true, fw::grip_state::reached});
    (void)v.feed(fw::QueryHoming{}, fw::StateCode{fw::homing_state::homing});
    CHECK(v.profile.in_motion(v.image));
    (void)v.feed(fw::QueryHoming{}, fw::StateCode{fw::homing_state::beyond_limit});
    const auto alarms = v.profile.alarms(v.image);
    REQUIRE(alarms.size() == 1);
    CHECK(alarms[0].code == "beyond_limit");
}

TEST_CASE("wtec-ascii: the state and alarms of the definition's points are those the profile made in C++") {
    // Every field, in order, with its value and unit, as decode_wtec_uniform() and
    // WtecAsciiProfile::decode_state() made them before wtec-ascii.yaml named them as
    // points (and docs/mqtt.md lists).
    View v;
    const auto now = t0();
    const auto put = [&](Table table, std::uint16_t address, std::vector<std::uint16_t> values) {
        v.image.update(table, address, values, now);
    };
    put(Table::holding, 0x0200, {2});
    put(Table::holding, 0x0202, {0x11});
    put(Table::holding, 0x0204, {48});
    put(Table::holding, 0x0102, {1, 80, 100, 50});
    put(Table::holding, 0x0300, {2});
    put(Table::input, 0x1000, {0xFFFF, 0xFFFD, 3, 1, 5, 2});
    put(Table::input, 0x102A, {0x4373, 0x7465, 0x7020, 0x5B41, 0x5D31, 0x2E36, 0x3200, 0x0000});  // "Cstep [A]1.62"
    using F = fe::Field;
    const std::vector<F> expected{
        F{"init_state", std::string{"failed"}, ""},   F{"init_state_code", std::int64_t{2}, ""},
        F{"grip_state", std::string{"motor_released"}, ""}, F{"grip_state_code", std::int64_t{17}, ""},
        F{"position_pct", std::int64_t{48}, "%"},     F{"target_pct", std::int64_t{50}, "%"},
        F{"force_pct", std::int64_t{80}, "%"},        F{"speed_pct", std::int64_t{100}, "%"},
        F{"estop", true, ""},                         F{"init_direction", std::string{"close"}, ""},
        F{"position_counts", std::int64_t{-3}, "count"}, F{"current", std::int64_t{3}, ""},
        F{"enabled", true, ""},                       F{"grip_code", std::int64_t{5}, ""},
        F{"homing_code", std::int64_t{2}, ""},        F{"firmware", std::string{"Cstep [A]1.62"}, ""},
    };
    CHECK(v.profile.decode_state(v.image).fields == expected);

    const fe::Alarm estop{"emergency_stop", "emergency stop latched; only initialising (0x0100 = 1) releases it",
                          fe::Severity::critical, "holding 0x0102"};
    CHECK(v.profile.alarms(v.image) ==
          std::vector<fe::Alarm>{{"init_failed", "initialisation (homing) failed; remove any obstacle and initialise again",
                                  fe::Severity::error, "holding 0x0200"},
                                 estop});
    put(Table::input, 0x1005, {3});  // the hook writes 0x0200 = 2 for it too
    CHECK(v.profile.alarms(v.image) ==
          std::vector<fe::Alarm>{{"beyond_limit",
                                  "homing went beyond the limit position; check the stroke and initialise again",
                                  fe::Severity::error, "holding 0x0200"},
                                 estop});
    put(Table::input, 0x1005, {1});
    put(Table::holding, 0x0200, {1});
    put(Table::holding, 0x0102, {0});
    CHECK(v.profile.alarms(v.image).empty());
    put(Table::holding, 0x0300, {7});
    CHECK(field<std::string>(v.profile.decode_state(v.image), "init_direction") == "unknown");
}

TEST_CASE("wtec-ascii: the same gripper through the RTU profile and the ASCII view reads the same") {
    View ascii_view;
    ascii_view.polled();

    fe::ProfileOptions rtu_options;
    const fe::WtecRtuProfile rtu{rtu_options};
    fe::RegisterImage rtu_image;
    const auto poll = [&](std::uint16_t address, std::vector<std::uint16_t> values) {
        const auto n = static_cast<std::uint16_t>(values.size());
        CHECK(rtu.apply(fe::ModbusPayload{read_holding(address, n)}, registers(0x03, std::move(values)), rtu_image,
                        t0())
                  .status == fe::ApplyStatus::applied);
    };
    // The same physical state as View::polled(), as the RTU firmware reports it.
    poll(0x0200, {1});
    poll(0x0202, {2});
    poll(0x0204, {48});
    poll(0x0102, {0, 80, 100, 50});
    poll(0x0300, {1});

    for (const std::uint16_t a : std::initializer_list<std::uint16_t>{0x0102, 0x0103, 0x0104, 0x0105, 0x0200, 0x0202, 0x0204, 0x0300}) {
        CAPTURE(a);
        REQUIRE(rtu_image.value(Table::holding, a).has_value());
        CHECK(ascii_view.image.value(Table::holding, a) == rtu_image.value(Table::holding, a));
    }
    const auto rtu_state = rtu.decode_state(rtu_image);
    const auto ascii_state = ascii_view.profile.decode_state(ascii_view.image);
    for (const char* name : {"init_state", "grip_state", "init_direction"}) {
        CHECK(field<std::string>(rtu_state, name) == field<std::string>(ascii_state, name));
    }
    for (const char* name : {"position_pct", "target_pct", "force_pct", "speed_pct", "init_state_code",
                             "grip_state_code"}) {
        CHECK(field<std::int64_t>(rtu_state, name) == field<std::int64_t>(ascii_state, name));
    }
    CHECK(field<bool>(rtu_state, "estop") == field<bool>(ascii_state, "estop"));
    CHECK(rtu.alarms(rtu_image) == ascii_view.profile.alarms(ascii_view.image));
    CHECK(rtu.in_motion(rtu_image) == ascii_view.profile.in_motion(ascii_view.image));

    // And a client's read gets the same answer either way.
    const auto request = read_holding(0x0102, 4);
    const std::vector<fe::Reply> rtu_reply{registers(0x03, {0, 80, 100, 50})};
    const auto from_rtu = rtu.respond(request, rtu_reply, rtu_image);
    const auto from_ascii = ascii_view.exchange(request, {gripper(5000, 80, 0xFF), driver(100)});
    CHECK(from_rtu == from_ascii);
    CHECK(from_rtu == fp::Response{fp::ReadRegistersResponse{0x03, {0, 80, 100, 50}}});

    // The same writes are accepted or refused alike.
    for (const auto& r : {write_single(0x0103, 19), write_single(0x0105, 101), write_single(0x0300, 0),
                          write_single(0x0102, 0), write_single(0x0101, 1), write_multiple(0x0103, {50, 50, 50})}) {
        CHECK(rtu.validate(r, rtu_image) == ascii_view.profile.validate(r, ascii_view.image));
    }
}
