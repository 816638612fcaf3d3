// WTEC-485 in Modbus-RTU mode against seed 003 part 2 (frames from tables 2.2-2.12).
#include <doctest/doctest.h>

#include <vector>

#include "engine/profiles/wtec_rtu_profile.hpp"
#include "support.hpp"

namespace {

using namespace fbt;
using fe::Table;
using fp::ExceptionCode;

struct Rtu {
    fe::ProfileOptions options;
    fe::WtecRtuProfile profile{options};
    fe::RegisterImage image;
    std::optional<ExceptionCode> check(const fp::Request& r) const { return profile.validate(r, image); }
    void set(std::uint16_t address, std::uint16_t value) {
        image.update(Table::holding, address, std::vector<std::uint16_t>{value}, t0());
    }
};

}  // namespace

TEST_CASE("wtec-rtu: function codes; FC16 goes out as FC06s") {
    const Rtu w;
    CHECK(w.profile.type() == fe::DeviceType::wtec_rtu);
    CHECK(w.profile.broadcast_address() == fieldbridge::core::BusAddress{0});
    CHECK(w.check(read_input(0x0200, 1)) == ExceptionCode::illegal_function);
    CHECK(w.check(fp::ReadExceptionStatusRequest{}) == ExceptionCode::illegal_function);

    // Seed 003 table 2.2 frames, PDU only: force 80 % is 01 06 01 03 00 50 78 0A.
    const auto one = w.profile.to_line(write_single(0x0103, 80), w.image);
    REQUIRE(one.size() == 1);
    CHECK(pdu_hex(one[0]) == "06 01 03 00 50");
    const auto request = write_multiple(0x0103, {80, 50, 50});
    const auto three = w.profile.to_line(request, w.image);
    REQUIRE(three.size() == 3);
    CHECK(pdu_hex(three[0]) == "06 01 03 00 50");
    CHECK(pdu_hex(three[1]) == "06 01 04 00 32");
    CHECK(pdu_hex(three[2]) == "06 01 05 00 32");

    std::vector<fe::Reply> acks{modbus(fp::WriteSingleResponse{0x06, 0x0103, 80}),
                                modbus(fp::WriteSingleResponse{0x06, 0x0104, 50}),
                                modbus(fp::WriteSingleResponse{0x06, 0x0105, 50})};
    CHECK(w.profile.respond(request, acks, w.image) == fp::Response{fp::WriteMultipleResponse{0x10, 0x0103, 3}});
    // Stopped at the second: its exception, under FC16.
    acks.resize(1);
    acks.push_back(device_exception(0x06, ExceptionCode::server_device_busy));
    CHECK(w.profile.respond(request, acks, w.image) ==
          fp::Response{fp::ExceptionResponse{0x10, ExceptionCode::server_device_busy}});
    // Fewer acknowledgements than commands and no exception: 0x0B.
    acks.resize(1);
    CHECK(w.profile.respond(request, acks, w.image) ==
          fp::Response{fp::ExceptionResponse{0x10, ExceptionCode::gateway_target_failed}});
}

TEST_CASE("wtec-rtu: 0x02 for holes and wrong directions, 0x03 for ranges, 0x01 for protected") {
    const Rtu w;
    CHECK(w.check(write_single(0x0101, 1)) == ExceptionCode::illegal_data_address);
    CHECK(w.check(read_holding(0x0100, 1)) == ExceptionCode::illegal_data_address);  // write-only
    CHECK(w.check(read_holding(0x0200, 5)) == ExceptionCode::illegal_data_address);  // 0x0201, 0x0203
    CHECK(w.check(write_single(0x0200, 1)) == ExceptionCode::illegal_data_address);  // read-only
    CHECK_FALSE(w.check(read_holding(0x0102, 4)));
    CHECK_FALSE(w.check(read_holding(0x0302, 2)));

    CHECK(w.check(write_single(0x0100, 0)) == ExceptionCode::illegal_data_value);
    CHECK_FALSE(w.check(write_single(0x0100, 1)));
    CHECK(w.check(write_single(0x0102, 0)) == ExceptionCode::illegal_data_value);
    CHECK(w.check(write_single(0x0103, 19)) == ExceptionCode::illegal_data_value);
    CHECK(w.check(write_single(0x0103, 101)) == ExceptionCode::illegal_data_value);
    CHECK_FALSE(w.check(write_single(0x0103, 20)));
    CHECK(w.check(write_single(0x0104, 0)) == ExceptionCode::illegal_data_value);
    CHECK(w.check(write_single(0x0105, 101)) == ExceptionCode::illegal_data_value);
    CHECK_FALSE(w.check(write_single(0x0105, 0)));
    CHECK(w.check(write_single(0x0300, 3)) == ExceptionCode::illegal_data_value);
    CHECK(w.check(write_multiple(0x0103, {50, 50, 120})) == ExceptionCode::illegal_data_value);

    CHECK(w.check(write_single(0x0302, 1)) == ExceptionCode::illegal_function);
    CHECK(w.check(write_single(0x0303, 5)) == ExceptionCode::illegal_function);
    fe::ProfileOptions allow;
    allow.allow_protected = true;
    const fe::WtecRtuProfile permissive{allow};
    CHECK_FALSE(permissive.validate(write_single(0x0303, 5), w.image));
    CHECK(permissive.validate(write_single(0x0303, 254), w.image) == ExceptionCode::illegal_data_value);
    CHECK(permissive.validate(write_single(0x0303, 0), w.image) == ExceptionCode::illegal_data_value);
}

TEST_CASE("wtec-rtu: classification") {
    const Rtu w;
    const auto estop = w.profile.classify(write_single(0x0102, 1));
    CHECK(estop.urgent_stop);
    CHECK(estop.motion);
    CHECK(w.profile.classify(write_single(0x0100, 1)).motion);
    CHECK(w.profile.classify(write_single(0x0105, 50)).motion);
    CHECK_FALSE(w.profile.classify(write_single(0x0103, 50)).motion);
    CHECK(w.profile.classify(write_single(0x0302, 1)).protected_write);
    CHECK(w.profile.classify(write_multiple(0x0102, {1, 50})).urgent_stop);
}

TEST_CASE("wtec-rtu: poll plan keeps the holes: three status reads") {
    const Rtu w;
    std::vector<std::string> seen;
    const fe::PollPlan plan = w.profile.poll_plan();
    for (const auto& item : plan.items()) {
        seen.push_back(std::string{fe::to_string(item.poll_class)} + " " + pdu_hex(item.payload) +
                       (item.motion ? " motion" : ""));
    }
    const std::vector<std::string> expected{
        "fast 03 02 00 00 01 motion", "fast 03 02 02 00 01 motion", "fast 03 02 04 00 01 motion",
        "slow 03 01 02 00 04",        "slow 03 03 00 00 01",        "slow 03 03 02 00 02",
    };
    CHECK(seen == expected);
}

TEST_CASE("wtec-rtu: state, motion and alarms from the grip and init states") {
    Rtu w;
    // Seed 003 table 2.8 example: 01 03 02 00 02 = object gripped.
    (void)w.profile.apply(fe::ModbusPayload{read_holding(0x0202, 1)}, registers(0x03, {2}), w.image, t0());
    (void)w.profile.apply(fe::ModbusPayload{read_holding(0x0200, 1)}, registers(0x03, {1}), w.image, t0());
    auto s = w.profile.decode_state(w.image);
    CHECK(field<std::string>(s, "grip_state") == "gripped");
    CHECK(field<std::string>(s, "init_state") == "initialized");
    CHECK_FALSE(w.profile.in_motion(w.image));
    CHECK(w.profile.alarms(w.image).empty());

    w.set(0x0202, 0);
    CHECK(w.profile.in_motion(w.image));
    w.set(0x0202, 1);
    w.set(0x0200, 9);
    CHECK(w.profile.in_motion(w.image));
    CHECK(field<std::string>(w.profile.decode_state(w.image), "init_state") == "initializing");

    w.set(0x0200, 2);
    w.set(0x0102, 1);
    const auto alarms = w.profile.alarms(w.image);
    REQUIRE(alarms.size() == 2);
    CHECK(alarms[0].code == "init_failed");
    CHECK(alarms[1].code == "emergency_stop");
    CHECK(alarms[1].severity == fe::Severity::critical);

    w.set(0x0202, 11);
    CHECK(field<std::string>(w.profile.decode_state(w.image), "grip_state") == "motor_released");
    w.set(0x0202, 0x11);
    CHECK(field<std::string>(w.profile.decode_state(w.image), "grip_state") == "motor_released");

    // An acknowledged FC06 lands in the image; write-only 0x0100 does not.
    (void)w.profile.apply(fe::ModbusPayload{write_single(0x0103, 80)}, modbus(fp::WriteSingleResponse{0x06, 0x0103, 80}),
                          w.image, t0());
    CHECK(w.image.value(Table::holding, 0x0103) == 80);
    (void)w.profile.apply(fe::ModbusPayload{write_single(0x0100, 1)}, modbus(fp::WriteSingleResponse{0x06, 0x0100, 1}),
                          w.image, t0());
    CHECK_FALSE(w.image.value(Table::holding, 0x0100).has_value());
    (void)w.profile.apply(fe::ModbusPayload{read_holding(0x0302, 2)}, registers(0x03, {1, 5}), w.image, t0());
    s = w.profile.decode_state(w.image);
    CHECK(field<bool>(s, "saved"));
    CHECK(field<std::int64_t>(s, "device_id") == 5);
}
