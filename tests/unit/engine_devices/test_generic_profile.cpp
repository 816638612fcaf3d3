// Generic Modbus-RTU device: the configured blocks are the map.
#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include "engine/profiles/generic_profile.hpp"
#include "engine/profiles/profile_factory.hpp"
#include "support.hpp"

namespace {

using namespace fbt;
using fe::Table;
using fp::ExceptionCode;
using std::chrono::milliseconds;

fe::ProfileOptions blocks(std::vector<fe::GenericBlock> b) {
    fe::ProfileOptions o;
    o.blocks = std::move(b);
    return o;
}

const std::vector<fe::GenericBlock> plant{
    {Table::holding, 0x0000, 10, milliseconds{100}, true},
    {Table::holding, 0x000A, 5, milliseconds{100}, false},  // touches the first, same period
    {Table::input, 0x0100, 4, milliseconds{1000}, false},
    {Table::coils, 0x0000, 16, milliseconds{500}, true},
};

std::string error_of(const fe::ProfileOptions& o) {
    try {
        (void)fe::make_profile(fe::DeviceType::modbus, o);
    } catch (const fe::ProfileError& e) {
        return e.what();
    }
    return "";
}

}  // namespace

TEST_CASE("generic: requests inside the blocks pass, others are refused locally") {
    const fe::GenericProfile g{blocks(plant)};
    const fe::RegisterImage image;
    CHECK(g.type() == fe::DeviceType::modbus);
    CHECK_FALSE(g.validate(read_holding(0, 15), image));
    CHECK(g.validate(read_holding(0, 16), image) == ExceptionCode::illegal_data_address);
    CHECK(g.validate(read_input(0x00FF, 2), image) == ExceptionCode::illegal_data_address);
    CHECK_FALSE(g.validate(read_input(0x0100, 4), image));
    CHECK(g.validate(read_bits(fp::fc::read_discrete_inputs, 0, 1), image) == ExceptionCode::illegal_data_address);
    CHECK_FALSE(g.validate(read_bits(fp::fc::read_coils, 0, 16), image));
    CHECK_FALSE(g.validate(write_multiple(0, std::vector<std::uint16_t>(10, 7)), image));
    CHECK(g.validate(write_multiple(0, std::vector<std::uint16_t>(11, 7)), image) ==
          ExceptionCode::illegal_data_address);  // 0x000A is read-only
    CHECK(g.validate(write_single(0x000A, 1), image) == ExceptionCode::illegal_data_address);
    CHECK_FALSE(g.validate(fp::WriteSingleCoilRequest{3, true}, image));
    CHECK_FALSE(g.validate(fp::WriteMultipleCoilsRequest{0, std::vector<bool>(16, true)}, image));
    CHECK(g.validate(fp::ReadExceptionStatusRequest{}, image) == ExceptionCode::illegal_function);
    CHECK(g.validate(fp::ReadWriteRegistersRequest{0, 1, 0, {1}}, image) == ExceptionCode::illegal_function);
    CHECK(g.validate(read_holding(0, 0), image) == ExceptionCode::illegal_data_value);

    const auto c = g.classify(write_single(0, 1));
    CHECK(c.write);
    CHECK_FALSE(c.motion);
    CHECK_FALSE(c.urgent_stop);
    CHECK_FALSE(c.protected_write);
}

TEST_CASE("generic: poll plan merges touching blocks of one period") {
    const fe::GenericProfile g{blocks(plant)};
    std::vector<std::string> seen;
    const fe::PollPlan plan = g.poll_plan();
    for (const auto& item : plan.items()) {
        seen.push_back(pdu_hex(item.payload) + " @" +
                       std::to_string(std::chrono::duration_cast<milliseconds>(item.period).count()));
        CHECK(item.poll_class == fe::PollClass::custom);
    }
    const std::vector<std::string> expected{"01 00 00 00 10 @500", "03 00 00 00 0F @100", "04 01 00 00 04 @1000"};
    std::sort(seen.begin(), seen.end());
    CHECK(seen == expected);
}

TEST_CASE("generic: overlapping blocks; writes, replies, echo") {
    const fe::GenericProfile g{blocks({{Table::holding, 0, 10, milliseconds{100}, false},
                                       {Table::holding, 5, 10, milliseconds{1000}, true},
                                       {Table::coils, 0, 8, milliseconds{100}, true}})};
    fe::RegisterImage image;
    CHECK_FALSE(g.validate(read_holding(0, 15), image));
    CHECK_FALSE(g.validate(write_multiple(5, std::vector<std::uint16_t>(10, 1)), image));
    CHECK(g.validate(write_single(4, 1), image) == ExceptionCode::illegal_data_address);

    const fp::Request coil = fp::WriteSingleCoilRequest{3, true};
    const auto out = g.to_line(coil, image);
    REQUIRE(out.size() == 1);
    CHECK(pdu_hex(out[0]) == "05 00 03 FF 00");
    const std::vector<fe::Reply> ack{modbus(fp::WriteSingleResponse{0x05, 3, 0xFF00})};
    CHECK(g.apply(out[0], ack[0], image, t0()).status == fe::ApplyStatus::applied);
    CHECK(image.value(Table::coils, 3) == 1);
    CHECK(g.respond(coil, ack, image) == fp::Response{fp::WriteSingleResponse{0x05, 3, 0xFF00}});

    // A coil read answered with whole bytes: only the bits asked for.
    const fp::Request bits = read_bits(fp::fc::read_coils, 0, 3);
    const std::vector<fe::Reply> reply{modbus(fp::ReadBitsResponse{0x01, std::vector<bool>{1, 0, 1, 1, 1, 1, 1, 1}})};
    (void)g.apply(fe::ModbusPayload{bits}, reply[0], image, t0());
    CHECK(values_of(image, Table::coils, 0, 4) == std::vector<std::uint16_t>{1, 0, 1, 1});
    CHECK(g.respond(bits, reply, image) == fp::Response{fp::ReadBitsResponse{0x01, {true, false, true}}});

    CHECK(g.decode_state(image).fields.empty());
    CHECK(g.alarms(image).empty());
    CHECK_FALSE(g.in_motion(image));
}

TEST_CASE("generic: block options that cannot work are refused with a reason") {
    CHECK(error_of(blocks({})).find("no register blocks") != std::string::npos);
    CHECK(error_of(blocks({{Table::holding, 0, 0, milliseconds{100}, false}})).find("count must be 1-125") !=
          std::string::npos);
    CHECK(error_of(blocks({{Table::holding, 0, 126, milliseconds{100}, false}})).find("count must be 1-125") !=
          std::string::npos);
    CHECK(error_of(blocks({{Table::coils, 0, 2000, milliseconds{100}, false}})).empty());
    CHECK(error_of(blocks({{Table::coils, 0, 2001, milliseconds{100}, false}})).find("1-2000") != std::string::npos);
    CHECK(error_of(blocks({{Table::holding, 0xFFF0, 20, milliseconds{100}, false}})).find("0xFFFF") !=
          std::string::npos);
    CHECK(error_of(blocks({{Table::input, 0, 2, milliseconds{100}, true}})).find("writable") != std::string::npos);
    CHECK(error_of(blocks({{Table::holding, 0, 2, milliseconds{0}, false}})).find("period") != std::string::npos);
}
