// EXCD203MB profile against seed 002: pairs, word order, ranges, protected registers.
#include <doctest/doctest.h>

#include <vector>

#include "engine/profiles/excd_profile.hpp"
#include "support.hpp"

namespace {

using namespace fbt;
using fe::Table;
using fp::ExceptionCode;

fe::ProfileOptions with_order(fe::WordOrder order) {
    fe::ProfileOptions o;
    o.word_order = order;
    return o;
}

struct Excd {
    explicit Excd(fe::WordOrder order = fe::WordOrder::high_first) : profile(with_order(order)) {}
    fe::ExcdProfile profile;
    fe::RegisterImage image;
    std::optional<ExceptionCode> check(const fp::Request& r) const { return profile.validate(r, image); }
};

constexpr std::uint16_t solm_plus = 0x0014;

}  // namespace

TEST_CASE("excd: identity, broadcast 0xFF") {
    const Excd e;
    CHECK(e.profile.type() == fe::DeviceType::excd203mb);
    CHECK(e.profile.broadcast_address() == fieldbridge::core::BusAddress{0xFF});
}

TEST_CASE("excd: 0x01 for anything but FC03 / FC06 / FC10, and for protected registers") {
    const Excd e;
    CHECK(e.check(read_input(0x0200, 1)) == ExceptionCode::illegal_function);
    CHECK(e.check(read_bits(fp::fc::read_coils, 0, 1)) == ExceptionCode::illegal_function);
    CHECK(e.check(fp::ReadExceptionStatusRequest{}) == ExceptionCode::illegal_function);
    CHECK_FALSE(e.check(read_holding(0x0200, 11)));
    // save, id, idon, baude, mbus.
    CHECK(e.check(write_single(0x0303, 0)) == ExceptionCode::illegal_function);
    CHECK(e.check(write_single(0x0020, 5)) == ExceptionCode::illegal_function);
    CHECK(e.check(write_single(0x001F, 1)) == ExceptionCode::illegal_function);
    CHECK(e.check(write_multiple(0x002B, {0x0001, 0xC200})) == ExceptionCode::illegal_function);
    CHECK(e.check(write_single(0x003A, 0)) == ExceptionCode::illegal_function);
    CHECK(e.profile.classify(write_single(0x0303, 0)).protected_write);

    fe::ProfileOptions allow;
    allow.allow_protected = true;
    const fe::ExcdProfile permissive{allow};
    // Seed 002 §3c: "01 10 03 03 00 01 02 00 00" saves.
    CHECK_FALSE(permissive.validate(write_multiple(0x0303, {0}), e.image));
    CHECK_FALSE(permissive.validate(write_multiple(0x002B, {0x0001, 0xC200}), e.image));  // 115200
}

TEST_CASE("excd: 0x02 for holes, half pairs written, reads of commands, writes of queries") {
    const Excd e;
    CHECK(e.check(read_holding(0x003D, 1)) == ExceptionCode::illegal_data_address);
    CHECK(e.check(read_holding(0x020B, 1)) == ExceptionCode::illegal_data_address);
    CHECK(e.check(read_holding(0x0200, 12)) == ExceptionCode::illegal_data_address);  // runs into 0x020B
    // Half of solm+ written: FC06 to either word, FC16 starting or ending inside.
    CHECK(e.check(write_single(solm_plus, 0)) == ExceptionCode::illegal_data_address);
    CHECK(e.check(write_single(solm_plus + 1, 0)) == ExceptionCode::illegal_data_address);
    CHECK(e.check(write_multiple(0x0013, {1, 0x000C})) == ExceptionCode::illegal_data_address);
    CHECK(e.check(write_multiple(0x0015, {0x3500, 0xFF81})) == ExceptionCode::illegal_data_address);
    CHECK_FALSE(e.check(write_multiple(0x0013, {1, 0x000C, 0x3500})));
    // Reading half a pair is harmless: allowed.
    CHECK_FALSE(e.check(read_holding(0x0202, 1)));
    // abs (a motion command) is write-only; rabs (a query) is read-only.
    CHECK(e.check(read_holding(0x0100, 2)) == ExceptionCode::illegal_data_address);
    CHECK(e.check(write_multiple(0x0201, {0, 0})) == ExceptionCode::illegal_data_address);
    // The n-variables are pairs too: n02 is 0x0403-0x0404.
    CHECK_FALSE(e.check(write_multiple(0x0403, {0, 1})));
    CHECK(e.check(write_multiple(0x0404, {0, 1})) == ExceptionCode::illegal_data_address);
}

TEST_CASE("excd: 0x03 for values outside the manual's ranges") {
    const Excd e;
    CHECK(e.check(write_single(0x0012, 9)) == ExceptionCode::illegal_data_value);   // cur 0x0A-0x1E
    CHECK_FALSE(e.check(write_single(0x0012, 0x1E)));
    CHECK(e.check(write_single(0x0013, 3)) == ExceptionCode::illegal_data_value);   // solmsw 0-2
    // solm+ in 0xFF815A20..0x007EA5E0 (signed): 8300001 is too far, -8300000 is fine.
    CHECK(e.check(write_multiple(solm_plus, {0x007E, 0xA5E1})) == ExceptionCode::illegal_data_value);
    CHECK_FALSE(e.check(write_multiple(solm_plus, {0xFF81, 0x5A20})));
    CHECK(e.check(write_multiple(0x0002, {0, 0})) == ExceptionCode::illegal_data_value);  // htr >= 1
    CHECK(e.check(write_single(0x0108, 1)) == ExceptionCode::illegal_data_value);    // stop takes 0 only
    // Jog: +1, -1, continuous forward / reverse only.
    CHECK_FALSE(e.check(write_multiple(0x010A, {0x0000, 0x0001})));
    CHECK_FALSE(e.check(write_multiple(0x010A, {0xFFFF, 0xFFFF})));
    CHECK_FALSE(e.check(write_multiple(0x010A, {0x007E, 0xA5E0})));
    CHECK_FALSE(e.check(write_multiple(0x010A, {0xFF81, 0x5A20})));
    CHECK(e.check(write_multiple(0x010A, {0x0000, 0x0002})) == ExceptionCode::illegal_data_value);
}

TEST_CASE("excd: classification of motion and stops") {
    const Excd e;
    const auto abs = e.profile.classify(write_multiple(0x0100, {0, 1000}));
    CHECK(abs.motion);
    CHECK_FALSE(abs.urgent_stop);
    for (const std::uint16_t a : std::initializer_list<std::uint16_t>{0x0108, 0x0109, 0x010C}) {
        const auto stop = e.profile.classify(write_single(a, 0));
        CHECK(stop.motion);
        CHECK(stop.urgent_stop);
    }
    CHECK_FALSE(e.profile.classify(write_single(0x0107, 0)).urgent_stop);  // home
    CHECK(e.profile.classify(write_single(0x0107, 0)).motion);
    const auto param = e.profile.classify(write_single(0x0012, 20));
    CHECK(param.write);
    CHECK_FALSE(param.motion);
    CHECK_FALSE(param.idempotent);
}

TEST_CASE("excd: solm+ = 800000 is 00 0C 35 00 high word first (seed 002 example 2)") {
    const Excd high;
    const auto request = write_multiple(solm_plus, {0x000C, 0x3500});
    const auto out = high.profile.to_line(request, high.image);
    REQUIRE(out.size() == 1);
    CHECK(pdu_hex(out[0]) == "10 00 14 00 02 04 00 0C 35 00");

    // low_first: the client still writes high word first; the wire carries 35 00 00 0C.
    Excd low{fe::WordOrder::low_first};
    const auto swapped = low.profile.to_line(request, low.image);
    REQUIRE(swapped.size() == 1);
    CHECK(pdu_hex(swapped[0]) == "10 00 14 00 02 04 35 00 00 0C");
    // The acknowledged write lands in the image in northbound order.
    (void)low.profile.apply(swapped[0], modbus(fp::WriteMultipleResponse{0x10, solm_plus, 2}), low.image, t0());
    CHECK(values_of(low.image, Table::holding, solm_plus, 2) == std::vector<std::uint16_t>{0x000C, 0x3500});
    // Single registers next to pairs are not touched by the swap.
    const auto mixed = low.profile.to_line(write_multiple(0x0013, {1, 0x000C, 0x3500, 0xFFFF, 0xFFFF}), low.image);
    CHECK(pdu_hex(mixed[0]) == "10 00 13 00 05 0A 00 01 35 00 00 0C FF FF FF FF");
}

TEST_CASE("excd: reads in both word orders; low_first widens reads that cut a pair") {
    Excd high;
    const auto r1 = high.profile.to_line(read_holding(0x0201, 2), high.image);
    CHECK(pdu_hex(r1[0]) == "03 02 01 00 02");
    // Seed 002 example 3: rabs reads 00 00 00 00.
    const std::vector<fe::Reply> reply{registers(0x03, {0xFFFF, 0xFFFD})};
    (void)high.profile.apply(r1[0], reply[0], high.image, t0());
    CHECK(high.profile.respond(read_holding(0x0201, 2), reply, high.image) ==
          fp::Response{fp::ReadRegistersResponse{0x03, {0xFFFF, 0xFFFD}}});
    CHECK(field<std::int64_t>(high.profile.decode_state(high.image), "position") == -3);

    Excd low{fe::WordOrder::low_first};
    // rms + the high half of rabs: widened to the whole pair.
    const auto request = read_holding(0x0200, 2);
    const auto out = low.profile.to_line(request, low.image);
    REQUIRE(out.size() == 1);
    CHECK(pdu_hex(out[0]) == "03 02 00 00 03");
    // On the wire: rms = 7, rabs low word 0xFFFD, then high word 0xFFFF.
    const std::vector<fe::Reply> wire{registers(0x03, {7, 0xFFFD, 0xFFFF})};
    (void)low.profile.apply(out[0], wire[0], low.image, t0());
    CHECK(values_of(low.image, Table::holding, 0x0200, 3) == std::vector<std::uint16_t>{7, 0xFFFF, 0xFFFD});
    CHECK(low.profile.respond(request, wire, low.image) ==
          fp::Response{fp::ReadRegistersResponse{0x03, {7, 0xFFFF}}});
    CHECK(field<std::int64_t>(low.profile.decode_state(low.image), "position") == -3);

    // A raw read that cuts a pair (not from to_line) stores only what it can place.
    fe::RegisterImage fresh;
    (void)low.profile.apply(fe::ModbusPayload{read_holding(0x0200, 2)}, registers(0x03, {8, 0x1234}), fresh, t0());
    CHECK(fresh.value(Table::holding, 0x0200) == 8);
    CHECK_FALSE(fresh.value(Table::holding, 0x0201).has_value());
    CHECK_FALSE(fresh.value(Table::holding, 0x0202).has_value());

    // Widening past 125 registers splits the read in two.
    const auto big = low.profile.to_line(read_holding(0x0402, 125), low.image);  // n01 low .. n63 high
    REQUIRE(big.size() == 2);
    const auto& a = std::get<fp::ReadRegistersRequest>(request_of(big[0]));
    const auto& b = std::get<fp::ReadRegistersRequest>(request_of(big[1]));
    CHECK(a.address == 0x0401);
    CHECK(b.address == a.address + a.count);
    CHECK(b.address + b.count == 0x0402 + 125);  // n63 ends where the read ends
    CHECK(a.count <= 125);
    CHECK(b.count <= 125);
}

TEST_CASE("excd: poll plan, in_motion, alarms") {
    Excd e;
    std::vector<std::string> seen;
    const fe::PollPlan plan = e.profile.poll_plan();
    for (const auto& item : plan.items()) {
        seen.push_back(std::string{fe::to_string(item.poll_class)} + " " + pdu_hex(item.payload) +
                       (item.motion ? " motion" : ""));
    }
    const std::vector<std::string> expected{"fast 03 02 00 00 0B motion", "fast 03 02 D4 00 03 motion",
                                            "slow 03 00 00 00 32"};
    CHECK(seen == expected);

    CHECK_FALSE(e.profile.in_motion(e.image));  // unknown: not moving
    e.image.update(Table::holding, 0x0205, std::vector<std::uint16_t>{0}, t0());
    CHECK(e.profile.in_motion(e.image));
    CHECK(field<bool>(e.profile.decode_state(e.image), "busy"));
    e.image.update(Table::holding, 0x0205, std::vector<std::uint16_t>{1}, t0());
    CHECK_FALSE(e.profile.in_motion(e.image));

    CHECK(e.profile.alarms(e.image).empty());
    e.image.update(Table::holding, 0x02D4, std::vector<std::uint16_t>{0, 100, 0}, t0());
    CHECK(e.profile.alarms(e.image).empty());
    e.image.update(Table::holding, 0x02D6, std::vector<std::uint16_t>{3}, t0());
    const auto alarms = e.profile.alarms(e.image);
    REQUIRE(alarms.size() == 1);
    CHECK(alarms[0].code == "alarm");
    CHECK(alarms[0].source == "holding 0x02D6");
    const auto state = e.profile.decode_state(e.image);
    CHECK(field<std::int64_t>(state, "alarm_code") == 3);
    CHECK(field<std::int64_t>(state, "encoder") == 100);

    // Seed 002 example 4: rin reads 0x000F.
    (void)e.profile.apply(fe::ModbusPayload{read_holding(0x0203, 1)}, registers(0x03, {0x000F}), e.image, t0());
    CHECK(field<std::int64_t>(e.profile.decode_state(e.image), "inputs") == 15);
}

TEST_CASE("excd: a merged status block rejected with 0x02 is split") {
    Excd e;
    fe::PollPlan plan = e.profile.poll_plan();
    const fe::PollItem status = plan.items()[0];
    // The device answers the 11-register block with 0x02 (e.g. a firmware without rsa).
    const auto r = e.profile.apply(status.payload, device_exception(0x03, ExceptionCode::illegal_data_address),
                                   e.image, t0());
    CHECK(r.status == fe::ApplyStatus::device_exception);
    const auto halves = plan.on_block_rejected(status.id);
    REQUIRE(halves.size() == 2);
    // 9 units (rms, rabs pair, rin, rout, rby, sensor, ver pair, rse, rsa): 4 and 5,
    // never cutting rabs or ver.
    CHECK(pdu_hex(halves[0].payload) == "03 02 00 00 05");
    CHECK(pdu_hex(halves[1].payload) == "03 02 05 00 06");
}
