// HIWIN XEG profile against seed 001 (frames from its Appendix 1 and §4-5).
#include <doctest/doctest.h>

#include <chrono>
#include <vector>

#include "engine/profiles/profile_factory.hpp"
#include "engine/profiles/xeg_profile.hpp"
#include "support.hpp"

namespace {

using namespace fbt;
using fe::Table;
using fp::ExceptionCode;
using std::chrono::milliseconds;

constexpr std::uint16_t xeg_32 = 0x0A20;
constexpr std::uint16_t xeg_16 = 0x0A10;

struct Xeg {
    fe::ProfileOptions options;
    fe::XegProfile profile{options};
    fe::RegisterImage image;

    void model(std::uint16_t m) { image.update(Table::holding, 0x0600, std::vector<std::uint16_t>{m}, t0()); }
    std::optional<ExceptionCode> check(const fp::Request& r) const { return profile.validate(r, image); }
};

}  // namespace

TEST_CASE("xeg: identity") {
    const Xeg x;
    CHECK(x.profile.type() == fe::DeviceType::hiwin_xeg);
    CHECK(x.profile.bus() == fe::Bus::modbus_rtu);
    CHECK(x.profile.broadcast_address() == fieldbridge::core::BusAddress{0});
}

TEST_CASE("xeg: 0x01 for function codes the controller lacks") {
    Xeg x;
    CHECK(x.check(read_bits(fp::fc::read_coils, 0, 8)) == ExceptionCode::illegal_function);
    CHECK(x.check(fp::WriteSingleCoilRequest{0, true}) == ExceptionCode::illegal_function);
    CHECK(x.check(fp::ReadWriteRegistersRequest{0x0600, 1, 0x0610, {1}}) == ExceptionCode::illegal_function);
    CHECK(x.check(fp::OpaqueRequest{0x2B, {0x0E, 0x01, 0x00}}) == ExceptionCode::illegal_function);
    // FC07 is the controller's own (seed 001 §4.2.4).
    CHECK_FALSE(x.check(fp::ReadExceptionStatusRequest{}));
}

TEST_CASE("xeg: the model is writable with a default config, to the models of §3.3 only") {
    // Appendix 1 scenario 1 writes it first: not a protected register (spec §4).
    Xeg x;
    REQUIRE_FALSE(x.options.allow_protected);
    for (const std::uint16_t m : std::initializer_list<std::uint16_t>{0x0A10, 0x0A20, 0x0A21, 0x0A30, 0x0A40}) {
        CHECK_FALSE(x.check(write_multiple(0x0600, {m})));
        CHECK_FALSE(x.check(write_single(0x0600, m)));
    }
    for (const std::uint16_t m : std::initializer_list<std::uint16_t>{0x0000, 0x0A00, 0x0A22, 0x0A41, 0x0A64}) {
        CHECK(x.check(write_multiple(0x0600, {m})) == ExceptionCode::illegal_data_value);
    }
    CHECK(x.check(write_multiple(0x0600, {0x0A65})) == ExceptionCode::illegal_data_value);  // above 2660
}

TEST_CASE("xeg: an acknowledged model write is read back and its ranges apply at once") {
    Xeg x;
    x.model(xeg_32);
    CHECK_FALSE(x.check(write_single(0x0630, 3200)));
    const auto sent = x.profile.to_line(write_single(0x0600, xeg_16), x.image);
    REQUIRE(sent.size() == 1);
    const auto result =
        x.profile.apply(sent[0], modbus(fp::WriteMultipleResponse{0x10, 0x0600, 1}), x.image, t0());
    CHECK(result.status == fe::ApplyStatus::applied);
    // Appendix 1 scenario 3: FC03 0x0600 x1.
    REQUIRE(result.follow_up.has_value());
    REQUIRE(std::holds_alternative<fe::ModbusPayload>(*result.follow_up));
    CHECK(std::get<fe::ModbusPayload>(*result.follow_up).request == read_holding(0x0600, 1));
    // XEG-16 strokes 16 mm: 32.00 mm is out of range from now on.
    CHECK(x.image.value(Table::holding, 0x0600) == xeg_16);
    CHECK(x.check(write_single(0x0630, 3200)) == ExceptionCode::illegal_data_value);
    CHECK_FALSE(x.check(write_single(0x0630, 1600)));
    // The read back stores what the controller holds, and asks for nothing more.
    const auto back = x.profile.apply(*result.follow_up, registers(0x03, {xeg_16}), x.image, t0());
    CHECK_FALSE(back.follow_up.has_value());
    // Other writes and a refused model write ask for no read.
    CHECK_FALSE(x.profile
                    .apply(fe::ModbusPayload{write_multiple(0x0630, {1000, 5000, 1})},
                           modbus(fp::WriteMultipleResponse{0x10, 0x0630, 3}), x.image, t0())
                    .follow_up.has_value());
    const auto refused = x.profile.apply(sent[0], modbus(fp::ExceptionResponse{0x10, ExceptionCode::server_device_failure}),
                                         x.image, t0());
    REQUIRE(refused.follow_up.has_value());
    CHECK(std::get<fe::ModbusPayload>(*refused.follow_up).request == fp::Request{fp::ReadExceptionStatusRequest{}});
}

TEST_CASE("xeg: 0x02 outside the map, across a hole, wrong table") {
    Xeg x;
    // Seed 001 §5's own example: FC06 to 0x0611 is an address that does not exist.
    CHECK(x.check(write_single(0x0611, 1)) == ExceptionCode::illegal_data_address);
    // Move and expert blocks are separate: a write across 0x0633-0x063F is refused.
    CHECK(x.check(write_multiple(0x0632, std::vector<std::uint16_t>(15, 0))) == ExceptionCode::illegal_data_address);
    // 0x0302 is a hole between status and firmware; 0x0300-0x0306 crosses it.
    CHECK(x.check(read_input(0x0300, 7)) == ExceptionCode::illegal_data_address);
    CHECK_FALSE(x.check(read_input(0x0300, 2)));
    CHECK_FALSE(x.check(read_input(0x0303, 4)));
    // Discrete inputs 0x0008-0x000F are a hole.
    CHECK(x.check(read_bits(fp::fc::read_discrete_inputs, 0, 24)) == ExceptionCode::illegal_data_address);
    CHECK_FALSE(x.check(read_bits(fp::fc::read_discrete_inputs, 0x0010, 8)));
    // Holding registers read with FC04 are not input registers.
    CHECK(x.check(read_input(0x0600, 1)) == ExceptionCode::illegal_data_address);
    CHECK_FALSE(x.check(read_holding(0x0640, 7)));
}

TEST_CASE("xeg: 0x03 for quantities and values out of range, by model") {
    Xeg x;
    CHECK(x.check(read_holding(0x0600, 0)) == ExceptionCode::illegal_data_value);
    CHECK(x.check(read_holding(0x0600, 126)) == ExceptionCode::illegal_data_value);
    CHECK(x.check(write_single(0x0610, 2)) == ExceptionCode::illegal_data_value);
    CHECK(x.check(write_single(0x0601, 64)) == ExceptionCode::illegal_data_value);
    CHECK(x.check(write_single(0x0601, 0)) == ExceptionCode::illegal_data_value);
    CHECK_FALSE(x.check(write_single(0x0601, 63)));

    // Model unknown: XEG-64's limits (the widest).
    CHECK_FALSE(x.check(write_single(0x0630, 6400)));
    CHECK(x.check(write_single(0x0630, 6401)) == ExceptionCode::illegal_data_value);
    CHECK_FALSE(x.check(write_single(0x0645, 40)));

    x.model(xeg_32);
    CHECK(x.check(write_single(0x0630, 3201)) == ExceptionCode::illegal_data_value);
    CHECK_FALSE(x.check(write_single(0x0630, 3200)));
    CHECK(x.check(write_single(0x0631, 8001)) == ExceptionCode::illegal_data_value);
    CHECK(x.check(write_single(0x0644, 2001)) == ExceptionCode::illegal_data_value);
    // Appendix 1's expert write on an XEG-32: 10 mm, 80 mm/s, hold 5 mm, 20 mm/s, 100 %.
    CHECK_FALSE(x.check(write_multiple(0x0640, {0, 1000, 8000, 500, 2000, 100, 1})));
    // The same with 33 mm of holding stroke.
    CHECK(x.check(write_multiple(0x0640, {0, 1000, 8000, 3300, 2000, 100, 1})) == ExceptionCode::illegal_data_value);

    x.model(xeg_16);
    CHECK(x.check(write_single(0x0645, 45)) == ExceptionCode::illegal_data_value);  // XEG-16: 50-100 %
    CHECK_FALSE(x.check(write_single(0x0645, 50)));
    CHECK(x.check(write_single(0x0645, 101)) == ExceptionCode::illegal_data_value);
    CHECK(x.check(write_single(0x0642, 6001)) == ExceptionCode::illegal_data_value);
}

TEST_CASE("xeg: classification") {
    const Xeg x;
    const auto read = x.profile.classify(read_input(0x0300, 2));
    CHECK_FALSE(read.write);
    CHECK(read.idempotent);
    CHECK_FALSE(read.motion);

    const auto stop = x.profile.classify(write_single(0x0620, 1));
    CHECK(stop.write);
    CHECK(stop.motion);
    CHECK(stop.urgent_stop);
    CHECK_FALSE(stop.idempotent);
    CHECK_FALSE(x.profile.classify(write_single(0x0620, 0)).urgent_stop);

    for (const std::uint16_t a : std::initializer_list<std::uint16_t>{0x0601, 0x0610, 0x0630, 0x0631, 0x0632, 0x0640, 0x0646}) {
        const auto c = x.profile.classify(write_single(a, 1));
        CHECK(c.motion);
        CHECK_FALSE(c.urgent_stop);
    }
    const auto model = x.profile.classify(write_single(0x0600, xeg_32));
    CHECK(model.write);
    CHECK_FALSE(model.protected_write);
    CHECK_FALSE(model.motion);
}

TEST_CASE("xeg: FC06 goes on the wire as the manual's FC16 of one register") {
    const Xeg x;
    const auto payloads = x.profile.to_line(write_single(0x0610, 1), x.image);
    REQUIRE(payloads.size() == 1);
    // Appendix 1, "Write reset": 02 10 06 10 00 01 02 00 01 17 F0 (PDU without id and CRC).
    CHECK(pdu_hex(payloads[0]) == "10 06 10 00 01 02 00 01");

    // FC16 and reads pass unchanged (Appendix 1 "Write Expert").
    const auto expert = x.profile.to_line(write_multiple(0x0640, {0, 1000, 8000, 500, 2000, 100, 1}), x.image);
    REQUIRE(expert.size() == 1);
    CHECK(pdu_hex(expert[0]) == "10 06 40 00 07 0E 00 00 03 E8 1F 40 01 F4 07 D0 00 64 00 01");
    CHECK(pdu_hex(x.profile.to_line(read_input(0x0303, 4), x.image)[0]) == "04 03 03 00 04");

    // The client gets an FC06 echo; a device exception comes back under FC06.
    const std::vector<fe::Reply> ack{modbus(fp::WriteMultipleResponse{0x10, 0x0610, 1})};
    CHECK(x.profile.respond(write_single(0x0610, 1), ack, x.image) ==
          fp::Response{fp::WriteSingleResponse{0x06, 0x0610, 1}});
    const std::vector<fe::Reply> refused{device_exception(0x10, ExceptionCode::server_device_failure)};
    CHECK(x.profile.respond(write_single(0x0610, 1), refused, x.image) ==
          fp::Response{fp::ExceptionResponse{0x06, ExceptionCode::server_device_failure}});
    // No reply at all: 0x0B.
    CHECK(x.profile.respond(write_single(0x0610, 1), {}, x.image) ==
          fp::Response{fp::ExceptionResponse{0x06, ExceptionCode::gateway_target_failed}});
}

TEST_CASE("xeg: poll plan (spec §5)") {
    fe::ProfileOptions o;
    o.poll.fast = milliseconds{40};
    o.poll.slow = milliseconds{900};
    const fe::XegProfile profile{o};
    const fe::PollPlan plan = profile.poll_plan();
    std::vector<std::string> seen;
    for (const auto& item : plan.items()) {
        seen.push_back(std::string{fe::to_string(item.poll_class)} + " " + pdu_hex(item.payload) +
                       (item.motion ? " motion" : ""));
        if (item.poll_class == fe::PollClass::fast) CHECK(item.period == milliseconds{40});
        if (item.poll_class == fe::PollClass::slow) CHECK(item.period == milliseconds{900});
    }
    const std::vector<std::string> expected{
        "startup 03 06 00 00 01",  // model
        "startup 04 03 03 00 04",  // firmware
        "fast 04 03 00 00 02 motion",
        "slow 02 00 00 00 08",  // DI: 0x0008-0x000F is a hole, so two reads
        "slow 02 00 10 00 08",  // DO
    };
    CHECK(seen == expected);
}

TEST_CASE("xeg: applying replies (Appendix 1) and decoding the state") {
    Xeg x;
    const auto now = t0();
    // "Read firmware version: V3.0.1.884": 08 00 03 00 00 00 01 03 74.
    auto r = x.profile.apply(fe::ModbusPayload{read_input(0x0303, 4)},
                             registers(0x04, {0x0003, 0x0000, 0x0001, 0x0374}), x.image, now);
    CHECK(r.status == fe::ApplyStatus::applied);
    // "Read gripper model": 0A 20.
    (void)x.profile.apply(fe::ModbusPayload{read_holding(0x0600, 1)}, registers(0x03, {0x0A20}), x.image, now);
    // §4.2.3: 07 D0 00 02 = 20.00 mm, positioned.
    (void)x.profile.apply(fe::ModbusPayload{read_input(0x0300, 2)}, registers(0x04, {2000, 2}), x.image, now);
    // §4.2.1: 0x22 = bits 1 and 5.
    (void)x.profile.apply(fe::ModbusPayload{read_bits(0x02, 0, 8)},
                          modbus(fp::ReadBitsResponse{0x02, {false, true, false, false, false, true, false, false}}),
                          x.image, now);

    const fe::DecodedState s = x.profile.decode_state(x.image);
    CHECK(field<std::string>(s, "firmware") == "V3.0.1.884");
    CHECK(field<std::string>(s, "model") == "XEG-32");
    CHECK(field<std::string>(s, "status") == "positioned");
    CHECK(field<double>(s, "position_mm") == doctest::Approx(20.0));
    CHECK(field<bool>(s, "di_in2"));
    CHECK(field<bool>(s, "di_in6"));
    CHECK_FALSE(field<bool>(s, "di_in1"));
    CHECK(s.find("do_alm1") == nullptr);  // never read
    CHECK_FALSE(x.profile.in_motion(x.image));
    CHECK(x.profile.alarms(x.image).empty());

    // A read reply of the wrong length changes nothing.
    CHECK(x.profile.apply(fe::ModbusPayload{read_input(0x0300, 2)}, registers(0x04, {1}), x.image, now).status ==
          fe::ApplyStatus::not_applicable);
    CHECK(x.image.value(Table::input, 0x0300) == 2000);
}

TEST_CASE("xeg: the state and alarms of the definition's points are those the profile made in C++") {
    // Every field, in order, with its value and unit, as XegProfile::decode_state()
    // made them before hiwin-xeg.yaml named them as points (and docs/mqtt.md lists).
    Xeg x;
    const auto now = t0();
    x.image.update(Table::input, 0x0300, std::vector<std::uint16_t>{35, 8}, now);  // 0.35 mm, status 8
    x.image.update(Table::input, 0x0303, std::vector<std::uint16_t>{3, 0, 1, 884}, now);
    x.image.update(Table::holding, 0x0600, std::vector<std::uint16_t>{0x0A99}, now);
    x.image.update(Table::discrete_inputs, 0x0000, std::vector<std::uint16_t>{1, 0, 0, 0, 0, 0, 1, 0}, now);
    x.image.update(Table::discrete_inputs, 0x0010, std::vector<std::uint16_t>{0, 0, 1, 0, 0, 0, 0, 1}, now);
    using F = fe::Field;
    const std::vector<F> expected{
        F{"status", std::string{"unknown"}, ""},
        F{"status_code", std::int64_t{8}, ""},
        F{"position_mm", 0.35, "mm"},
        F{"model", std::string{"unknown (0x0A99)"}, ""},
        F{"firmware", std::string{"V3.0.1.884"}, ""},
        F{"di_in1", true, ""},  F{"do_pos", false, ""},  F{"di_in2", false, ""},  F{"do_hold", false, ""},
        F{"di_in3", false, ""}, F{"do_busy", true, ""},  F{"di_in4", false, ""},  F{"do_alm1", false, ""},
        F{"di_in5", false, ""}, F{"do_alm2", false, ""}, F{"di_in6", false, ""},  F{"do_chk1", false, ""},
        F{"di_start", true, ""}, F{"do_chk2", false, ""}, F{"di_di7", false, ""}, F{"do_chk3", true, ""},
    };
    CHECK(x.profile.decode_state(x.image).fields == expected);
    // 0.01 mm: the decimal, for every register value (raw / 100, not raw * 0.01).
    for (const std::uint16_t raw : {std::uint16_t{1}, std::uint16_t{35}, std::uint16_t{884}, std::uint16_t{6400},
                                    std::uint16_t{65535}}) {
        x.image.update(Table::input, 0x0300, std::vector<std::uint16_t>{raw}, now);
        CHECK(field<double>(x.profile.decode_state(x.image), "position_mm") == static_cast<double>(raw) / 100.0);
    }
    x.model(xeg_16);
    CHECK(field<std::string>(x.profile.decode_state(x.image), "model") == "XEG-16");
    CHECK(x.profile.decode_state(x.image).find("model_code") == nullptr);

    // The alarms, with their texts and sources.
    x.image.update(Table::input, 0x0301, std::vector<std::uint16_t>{6}, now);
    x.image.update(Table::discrete_inputs, 0x0013, std::vector<std::uint16_t>{1, 1}, now);
    const std::vector<fe::Alarm> alarms{
        {"home_alarm", "home reset failure: initialise (reset 0x0610) again after clearing the obstacle",
         fe::Severity::error, "input 0x0301"},
        {"alm1", "alarm output ALM1 is on", fe::Severity::error, "discrete input 0x0013"},
        {"alm2", "alarm output ALM2 is on", fe::Severity::error, "discrete input 0x0014"},
    };
    CHECK(x.profile.alarms(x.image) == alarms);
    const std::vector<std::pair<std::uint16_t, std::string>> texts{
        {4, "position failure: the gripper did not reach the position"},
        {5, "move alarm: the motion was obstructed or failed"},
        {7, "emergency stop: the emergency circuit is open; close it and reset"}};
    for (const auto& [status, text] : texts) {
        x.image.update(Table::input, 0x0301, std::vector<std::uint16_t>{status}, now);
        CHECK(x.profile.alarms(x.image).front().text == text);
    }
}

TEST_CASE("xeg: acknowledged writes update the image; auto-reset registers read 0") {
    Xeg x;
    // FC06 0x0631 went out as FC16.
    const auto sent = x.profile.to_line(write_single(0x0631, 8000), x.image);
    (void)x.profile.apply(sent[0], modbus(fp::WriteMultipleResponse{0x10, 0x0631, 1}), x.image, t0());
    CHECK(x.image.value(Table::holding, 0x0631) == 8000);
    // Move with its flag: the flag auto-resets (§3.4.2 "Auto Reset O").
    (void)x.profile.apply(fe::ModbusPayload{write_multiple(0x0630, {3200, 8000, 1})},
                          modbus(fp::WriteMultipleResponse{0x10, 0x0630, 3}), x.image, t0());
    CHECK(values_of(x.image, Table::holding, 0x0630, 3) == std::vector<std::uint16_t>{3200, 8000, 0});
    (void)x.profile.apply(fe::ModbusPayload{write_multiple(0x0610, {1})},
                          modbus(fp::WriteMultipleResponse{0x10, 0x0610, 1}), x.image, t0());
    CHECK(x.image.value(Table::holding, 0x0610) == 0);
    // The respond() of a read of them is the device's reply.
    const std::vector<fe::Reply> reply{registers(0x03, {3200, 8000, 0})};
    CHECK(x.profile.respond(read_holding(0x0630, 3), reply, x.image) ==
          fp::Response{fp::ReadRegistersResponse{0x03, {3200, 8000, 0}}});
}

TEST_CASE("xeg: in motion while working; alarms for status 4-7 and ALM1 / ALM2") {
    Xeg x;
    x.image.update(Table::input, 0x0301, std::vector<std::uint16_t>{1}, t0());
    CHECK(x.profile.in_motion(x.image));
    CHECK(field<std::string>(x.profile.decode_state(x.image), "status") == "working");

    const std::vector<std::pair<std::uint16_t, std::string>> alarm_codes{
        {4, "position_alarm"}, {5, "move_alarm"}, {6, "home_alarm"}, {7, "emergency_stop"}};
    for (const auto& [status, code] : alarm_codes) {
        x.image.update(Table::input, 0x0301, std::vector<std::uint16_t>{status}, t0());
        const auto alarms = x.profile.alarms(x.image);
        REQUIRE(alarms.size() == 1);
        CHECK(alarms[0].code == code);
        CHECK(alarms[0].source == "input 0x0301");
        CHECK(alarms[0].severity == (status == 7 ? fe::Severity::critical : fe::Severity::error));
        CHECK_FALSE(x.profile.in_motion(x.image));
    }
    x.image.update(Table::input, 0x0301, std::vector<std::uint16_t>{3}, t0());
    CHECK(x.profile.alarms(x.image).empty());
    x.image.update(Table::discrete_inputs, 0x0010, std::vector<std::uint16_t>{0, 1, 0, 1, 1, 0, 0, 0}, t0());
    const auto alarms = x.profile.alarms(x.image);
    REQUIRE(alarms.size() == 2);
    CHECK(alarms[0].code == "alm1");
    CHECK(alarms[1].code == "alm2");
    CHECK(field<bool>(x.profile.decode_state(x.image), "do_hold"));
}

TEST_CASE("xeg: exception 0x04 asks for FC07, whose status is decoded") {
    Xeg x;
    const auto r = x.profile.apply(fe::ModbusPayload{write_multiple(0x0630, {3200, 8000, 1})},
                                   device_exception(0x10, ExceptionCode::server_device_failure), x.image, t0());
    CHECK(r.status == fe::ApplyStatus::device_exception);
    CHECK(r.exception == ExceptionCode::server_device_failure);
    REQUIRE(r.follow_up.has_value());
    CHECK(pdu_hex(*r.follow_up) == "07");

    // Seed 001 §4.2.4: 02 07 02 = emergency stop.
    const auto status = x.profile.apply(*r.follow_up, modbus(fp::ReadExceptionStatusResponse{0x02}), x.image, t0());
    CHECK(status.status == fe::ApplyStatus::applied);
    REQUIRE(status.notice.has_value());
    CHECK(status.notice->code == 0x02);
    CHECK(status.notice->text == "exception status 0x02: emergency stop");
    // 0x00 is "no error": applied, nothing to report.
    const auto clear = x.profile.apply(*r.follow_up, modbus(fp::ReadExceptionStatusResponse{0x00}), x.image, t0());
    CHECK(clear.status == fe::ApplyStatus::applied);
    CHECK_FALSE(clear.notice.has_value());
    CHECK(fe::xeg_exception_status_text(0x12) == "reset error");
    CHECK(fe::xeg_exception_status_text(0x99) == "exception status not in the manual");

    // Other exceptions ask for nothing; a failed read marks its registers stale.
    x.image.update(Table::input, 0x0300, std::vector<std::uint16_t>{1, 2}, t0());
    const auto e2 = x.profile.apply(fe::ModbusPayload{read_input(0x0300, 2)},
                                    device_exception(0x04, ExceptionCode::illegal_data_address), x.image, t0());
    CHECK_FALSE(e2.follow_up.has_value());
    CHECK(x.image.quality(Table::input, 0x0300) == fe::Quality::stale);
    // An exception to another function does not answer this request.
    CHECK(x.profile.apply(fe::ModbusPayload{read_input(0x0300, 2)},
                          device_exception(0x03, ExceptionCode::illegal_data_address), x.image, t0())
              .status == fe::ApplyStatus::not_applicable);
}

TEST_CASE("xeg: model limits table (§3.4.2)") {
    const auto l = fe::xeg_model_limits(0x0A21);
    REQUIRE(l.has_value());
    CHECK(l->name == "XEG-32-PR");
    CHECK(l->stroke == 3200);
    CHECK(l->speed == 6000);
    CHECK(l->hold_speed == 1000);
    CHECK(l->force_min == 50);
    CHECK_FALSE(fe::xeg_model_limits(0x0A50).has_value());
    CHECK(fe::xeg_widest_limits().stroke == 6400);
    CHECK(fe::make_profile(fe::DeviceType::hiwin_xeg, {})->type() == fe::DeviceType::hiwin_xeg);
}
