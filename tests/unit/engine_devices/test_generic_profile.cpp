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
    CHECK(g.validate(read_holding(0, 0), image) == ExceptionCode::illegal_data_value);
    CHECK(g.validate(fp::OpaqueRequest{0x41, {}}, image) == ExceptionCode::illegal_function);

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

TEST_CASE("generic: FC11 report server ID, FC16 mask write and FC17 read/write go through the block checks") {
    const fe::GenericProfile g{blocks(plant)};
    fe::RegisterImage image;
    // FC11 carries no data; the device's answer is passed through as it came.
    const fp::Request server_id = fp::OpaqueRequest{0x11, {}};
    CHECK_FALSE(g.validate(server_id, image));
    CHECK(g.validate(fp::OpaqueRequest{0x11, {0x00}}, image) == ExceptionCode::illegal_data_value);
    CHECK_FALSE(g.classify(server_id).write);
    const fp::Response id_reply = fp::OpaqueResponse{0x11, {0x03, 0x07, 0xFF, 0x4C}};
    CHECK(g.respond(server_id, std::vector<fe::Reply>{modbus(id_reply)}, image) == id_reply);

    // FC16: only a register of a writable holding block, as FC06.
    const fp::Request mask = fp::MaskWriteRegisterRequest{0x0002, 0x00F2, 0x0025};
    CHECK_FALSE(g.validate(mask, image));
    CHECK(g.validate(fp::MaskWriteRegisterRequest{0x000A, 0, 1}, image) == ExceptionCode::illegal_data_address);
    CHECK(g.validate(fp::MaskWriteRegisterRequest{0x0020, 0, 1}, image) == ExceptionCode::illegal_data_address);
    const auto c = g.classify(mask);
    CHECK(c.write);
    CHECK_FALSE(c.idempotent);
    image.update(Table::holding, 0x0002, std::vector<std::uint16_t>{0x0012}, t0());
    const auto out = g.to_line(mask, image);
    REQUIRE(out.size() == 1);
    CHECK(pdu_hex(out[0]) == "16 00 02 00 F2 00 25");
    const fe::Reply echo = modbus(fp::MaskWriteResponse{0x0002, 0x00F2, 0x0025});
    CHECK(g.apply(out[0], echo, image, t0()).status == fe::ApplyStatus::applied);
    // What it holds now depends on what it held: read from the device again.
    CHECK(image.quality(Table::holding, 0x0002) == fe::Quality::stale);
    CHECK(g.respond(mask, std::vector<fe::Reply>{echo}, image) == fp::Response{fp::MaskWriteResponse{2, 0xF2, 0x25}});

    // FC17: the write as an FC10 of it, the read as an FC03 of it.
    const fp::Request rw = fp::ReadWriteRegistersRequest{0x000A, 3, 0x0004, {0xAAAA, 0xBBBB}};
    CHECK_FALSE(g.validate(rw, image));
    CHECK(g.validate(fp::ReadWriteRegistersRequest{0x000A, 6, 0x0004, {1}}, image) ==
          ExceptionCode::illegal_data_address);  // the read runs past the blocks
    CHECK(g.validate(fp::ReadWriteRegistersRequest{0x0000, 1, 0x0009, {1, 2}}, image) ==
          ExceptionCode::illegal_data_address);  // the write reaches the read-only 0x000A
    CHECK(g.classify(rw).write);
    const fe::Reply read_back = modbus(fp::ReadRegistersResponse{0x17, {0x000A, 0x000B, 0x000C}});
    REQUIRE(g.to_line(rw, image).size() == 1);
    CHECK(g.apply(fe::ModbusPayload{rw}, read_back, image, t0()).status == fe::ApplyStatus::applied);
    CHECK(values_of(image, Table::holding, 0x0004, 2) == std::vector<std::uint16_t>{0xAAAA, 0xBBBB});
    CHECK(values_of(image, Table::holding, 0x000A, 3) == std::vector<std::uint16_t>{0x000A, 0x000B, 0x000C});
    CHECK(g.respond(rw, std::vector<fe::Reply>{read_back}, image) ==
          fp::Response{fp::ReadRegistersResponse{0x17, {0x000A, 0x000B, 0x000C}}});
}

TEST_CASE("generic: FC16 only on a plain 16-bit register (checked through the shared map rules)") {
    // A range, a stop value or half of a 32-bit pair: the value it would leave cannot be checked.
    std::vector<fe::RegisterDef> defs(3);
    defs[0].address = 0;
    defs[0].access = fe::Access::read_write;
    defs[1].address = 1;
    defs[1].access = fe::Access::read_write;
    defs[1].max = 100;
    defs[2].address = 2;
    defs[2].width = 2;
    defs[2].access = fe::Access::read_write;
    defs[2].max = 0xFFFFFFFF;
    const fe::RegisterMap map{defs};
    const std::vector<fieldbridge::core::FunctionCode> functions{fp::fn::mask_write_register};
    CHECK_FALSE(fe::validate_request(map, fp::MaskWriteRegisterRequest{0, 0, 1}, functions, false, {}));
    CHECK(fe::validate_request(map, fp::MaskWriteRegisterRequest{1, 0, 1}, functions, false, {}) ==
          ExceptionCode::illegal_data_value);
    CHECK(fe::validate_request(map, fp::MaskWriteRegisterRequest{2, 0, 1}, functions, false, {}) ==
          ExceptionCode::illegal_data_address);  // half a pair: the map's own rule
    CHECK(fe::validate_request(map, fp::WriteSingleRegisterRequest{0, 1}, functions, false, {}) ==
          ExceptionCode::illegal_function);
}
