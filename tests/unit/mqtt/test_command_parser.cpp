// MQTT commands -> Modbus requests per device type (the profiles' operations); what the parser and the profiles refuse.
#include <doctest/doctest.h>

#include "engine/profiles/excd_profile.hpp"
#include "engine/profiles/profile_factory.hpp"
#include "engine/profiles/wtec_common.hpp"
#include "engine/profiles/xeg_profile.hpp"
#include "northbound/mqtt/command_parser.hpp"
#include "northbound/upstream/r6_operations.hpp"

namespace {

namespace fe = fieldbridge::engine;
namespace fm = fieldbridge::northbound::mqtt;
namespace fp = fieldbridge::protocol;
namespace r6 = fieldbridge::northbound::r6;

using Registers = std::vector<fm::RawRegister>;

/// A WTEC register image that knows the init direction (holding 0x0300).
Registers init_direction(std::uint16_t direction) {
    return {fm::RawRegister{fe::Table::holding, 0x0204, 40}, fm::RawRegister{fe::Table::holding, 0x0300, direction}};
}

std::vector<fp::Request> requests(const std::string& payload, const fe::OperationSet& set, const Registers& registers = {}) {
    const auto result = fm::parse_command(payload, set, registers);
    if (const auto* error = std::get_if<fm::CommandError>(&result)) {
        FAIL_CHECK("refused: " << error->message);
        return {};
    }
    return std::get<fm::ParsedCommand>(result).requests;
}

fm::CommandError refused(const std::string& payload, const fe::OperationSet& set, const Registers& registers = {}) {
    const auto result = fm::parse_command(payload, set, registers);
    REQUIRE(std::holds_alternative<fm::CommandError>(result));
    return std::get<fm::CommandError>(result);
}

fp::Request fc06(std::uint16_t a, std::uint16_t v) { return fp::WriteSingleRegisterRequest{a, v}; }
fp::Request fc16(std::uint16_t a, std::vector<std::uint16_t> v) { return fp::WriteMultipleRegistersRequest{a, std::move(v)}; }

using Rs = std::vector<fp::Request>;

}  // namespace

TEST_CASE("commands: XEG ops (seed 001 section 3.4)") {
    CHECK(requests(R"({"id":1,"op":"reset"})", fe::xeg_operations()) == Rs{fc06(0x0610, 1)});
    CHECK(requests(R"({"id":1,"op":"stop"})", fe::xeg_operations()) == Rs{fc06(0x0620, 1)});
    CHECK(requests(R"({"id":1,"op":"move","position_mm":17.5,"speed_mm_s":20})", fe::xeg_operations()) ==
          Rs{fc16(0x0630, {1750, 2000, 1})});
    CHECK(requests(R"({"id":"e","op":"expert","direction":1,"stroke_mm":10,"speed_mm_s":20,"holding_stroke_mm":5,)"
                   R"("holding_speed_mm_s":10,"force_pct":60})",
                   fe::xeg_operations()) == Rs{fc16(0x0640, {1, 1000, 2000, 500, 1000, 60, 1})});
    CHECK(requests(R"({"id":1,"op":"trigger","index":5})", fe::xeg_operations()) == Rs{fc06(0x0601, 5)});
}

TEST_CASE("commands: EXCD203MB ops, 32-bit values high word first") {
    CHECK(requests(R"({"id":1,"op":"abs","position":1600000})", fe::excd_operations()) == Rs{fc16(0x0100, {0x0018, 0x6A00})});
    CHECK(requests(R"({"id":1,"op":"rel","distance":-1})", fe::excd_operations()) == Rs{fc16(0x0104, {0xFFFF, 0xFFFF})});
    CHECK(requests(R"({"id":1,"op":"home"})", fe::excd_operations()) == Rs{fc06(0x0107, 0)});
    CHECK(requests(R"({"id":1,"op":"stop"})", fe::excd_operations()) == Rs{fc06(0x0108, 0)});
    CHECK(requests(R"({"id":1,"op":"stop","immediate":true})", fe::excd_operations()) == Rs{fc06(0x0109, 0)});
    CHECK(requests(R"({"id":1,"op":"jog","direction":"reverse","mode":"continuous"})", fe::excd_operations()) ==
          Rs{fc16(0x010A, {0xFF81, 0x5A20})});
    CHECK(requests(R"({"id":1,"op":"jog","direction":"forward","mode":"inch"})", fe::excd_operations()) ==
          Rs{fc16(0x010A, {0, 1})});
    CHECK(requests(R"({"id":1,"op":"jog_stop"})", fe::excd_operations()) == Rs{fc06(0x010C, 0)});
    CHECK(requests(R"({"id":1,"op":"set_register","address":18,"value":20})", fe::excd_operations()) == Rs{fc06(0x0012, 20)});
}

TEST_CASE("commands: WTEC ops on the uniform map") {
    CHECK(requests(R"({"id":1,"op":"init"})", fe::wtec_operations()) == Rs{fc06(0x0100, 1)});
    CHECK(requests(R"({"id":1,"op":"position","percent":40})", fe::wtec_operations()) == Rs{fc06(0x0105, 40)});
    CHECK(requests(R"({"id":1,"op":"force","percent":20})", fe::wtec_operations()) == Rs{fc06(0x0103, 20)});
    CHECK(requests(R"({"id":1,"op":"speed","percent":100})", fe::wtec_operations()) == Rs{fc06(0x0104, 100)});
    CHECK(requests(R"({"id":1,"op":"estop"})", fe::wtec_operations()) == Rs{fc06(0x0102, 1)});
}

TEST_CASE("commands: WTEC grip closes and release opens, whichever end the gripper homes to") {
    // Init direction 1 (the default): homes at the open end, so 0 % is open, 100 % closed.
    const Registers open_home = init_direction(1);
    CHECK(requests(R"({"id":1,"op":"grip"})", fe::wtec_operations(), open_home) == Rs{fc06(0x0105, 100)});
    CHECK(requests(R"({"id":1,"op":"grip","force_pct":50,"speed_pct":80})", fe::wtec_operations(), open_home) ==
          Rs{fc06(0x0103, 50), fc06(0x0104, 80), fc06(0x0105, 100)});
    CHECK(requests(R"({"id":1,"op":"release","speed_pct":30})", fe::wtec_operations(), open_home) ==
          Rs{fc06(0x0104, 30), fc06(0x0105, 0)});
    // Init direction 2: homes at the closed end, so 0 % is closed, 100 % open.
    const Registers closed_home = init_direction(2);
    CHECK(requests(R"({"id":1,"op":"grip"})", fe::wtec_operations(), closed_home) == Rs{fc06(0x0105, 0)});
    CHECK(requests(R"({"id":1,"op":"release","force_pct":20})", fe::wtec_operations(), closed_home) ==
          Rs{fc06(0x0103, 20), fc06(0x0105, 100)});
    // 0x0300 of another table (an XEG's position input register) is not the direction.
    const Registers other_table{fm::RawRegister{fe::Table::input, 0x0300, 1}};
    CHECK(refused(R"({"id":1,"op":"grip"})", fe::wtec_operations(), other_table).kind ==
          fm::CommandErrorKind::state_unknown);
}

TEST_CASE("commands: WTEC grip / release before the init direction is known send nothing") {
    for (const char* op : {"grip", "release"}) {
        INFO(op);
        const auto unknown = refused(std::string(R"({"id":"g1","op":")") + op + R"("})", fe::wtec_operations());
        CHECK(unknown.kind == fm::CommandErrorKind::state_unknown);
        CHECK(fm::to_string(unknown.kind) == "state_unknown");
        CHECK(unknown.id == "g1");
        CHECK(unknown.op == op);
        CHECK(unknown.message.find("init direction") != std::string::npos);
        CHECK(unknown.message.find("not read") != std::string::npos);
        CHECK(unknown.message.find("retry") != std::string::npos);
        CHECK(unknown.message.find("'position'") != std::string::npos);
        // A mode the uniform view shows raw (neither FC nor FD) is no direction either.
        const auto odd = refused(std::string(R"({"id":"g2","op":")") + op + R"("})", fe::wtec_operations(),
                                 init_direction(0xFE));
        CHECK(odd.kind == fm::CommandErrorKind::state_unknown);
        CHECK(odd.message.find("254") != std::string::npos);
    }
    // Ops that do not depend on the direction need no registers.
    CHECK(requests(R"({"id":1,"op":"position","percent":0})", fe::wtec_operations()) == Rs{fc06(0x0105, 0)});
}

TEST_CASE("commands: R6 ops (seed 004 3.2.1, 3.2.2, 3.3.3)") {
    CHECK(requests(R"({"id":1,"op":"stop"})", r6::r6_operations()) == Rs{fc06(0x4E20, 1)});
    CHECK(requests(R"({"id":1,"op":"pause"})", r6::r6_operations()) == Rs{fc06(0x4E21, 1)});
    CHECK(requests(R"({"id":1,"op":"start"})", r6::r6_operations()) == Rs{fc06(0x4E23, 1)});
    CHECK(requests(R"({"id":1,"op":"clear_alarm","resume":"next"})", r6::r6_operations()) == Rs{fc06(0x4E25, 1)});
    CHECK(requests(R"({"id":1,"op":"clear_alarm","resume":"continue"})", r6::r6_operations()) == Rs{fc06(0x4E26, 1)});
    CHECK(requests(R"({"id":1,"op":"global_speed","percent":10})", r6::r6_operations()) == Rs{fc06(0x4EE8, 100)});
    CHECK(requests(R"({"id":1,"op":"output","board":0,"point":1,"on":true})", r6::r6_operations()) ==
          Rs{fc16(0x4E58, {0, 1, 1})});
}

TEST_CASE("commands: write_registers for every set, holding or coils") {
    for (const auto& set : {fe::xeg_operations(), fe::excd_operations(), fe::wtec_operations(), r6::r6_operations(),
                            fe::OperationSet{}}) {
        CHECK(requests(R"({"id":1,"op":"write_registers","address":16,"values":[1,2]})", set) == Rs{fc16(0x10, {1, 2})});
        CHECK(requests(R"({"id":1,"op":"write_registers","address":16,"values":[7]})", set) == Rs{fc06(0x10, 7)});
    }
    CHECK(requests(R"({"id":1,"op":"write_registers","table":"coils","address":3,"values":[1]})", fe::OperationSet{}) ==
          Rs{fp::WriteSingleCoilRequest{3, true}});
    CHECK(requests(R"({"id":1,"op":"write_registers","table":"coils","address":3,"values":[1,0]})",
                   fe::OperationSet{}) == Rs{fp::WriteMultipleCoilsRequest{3, {true, false}}});
}

TEST_CASE("commands: invalid commands are refused with a kind and a message, echoing the id when there is one") {
    using fm::CommandErrorKind;
    CHECK(refused("not json", fe::xeg_operations()).kind == CommandErrorKind::bad_json);
    CHECK(refused("[1,2]", fe::xeg_operations()).kind == CommandErrorKind::bad_json);
    CHECK(refused(R"({"op":"stop"})", fe::xeg_operations()).kind == CommandErrorKind::missing_id);
    CHECK(refused(R"({"id":true,"op":"stop"})", fe::xeg_operations()).kind == CommandErrorKind::missing_id);
    const auto unknown = refused(R"({"id":"a","op":"fly"})", fe::xeg_operations());
    CHECK(unknown.kind == CommandErrorKind::unknown_op);
    CHECK(unknown.id == "a");
    CHECK(unknown.message.find("move") != std::string::npos);  // lists the ops
    CHECK(refused(R"({"id":1,"op":"abs","position":1})", fe::xeg_operations()).kind == CommandErrorKind::unknown_op);
    CHECK(refused(R"({"id":1})", fe::xeg_operations()).kind == CommandErrorKind::unknown_op);
    const auto missing = refused(R"({"id":2,"op":"move","position_mm":1})", fe::xeg_operations());
    CHECK(missing.kind == CommandErrorKind::missing_field);
    CHECK(missing.id == 2);
    CHECK(missing.op == "move");
    CHECK(missing.message.find("speed_mm_s") != std::string::npos);
    CHECK(refused(R"({"id":1,"op":"move","position_mm":"1","speed_mm_s":1})", fe::xeg_operations()).kind ==
          CommandErrorKind::invalid_field);
    CHECK(refused(R"({"id":1,"op":"move","position_mm":-1,"speed_mm_s":1})", fe::xeg_operations()).kind ==
          CommandErrorKind::out_of_range);
    CHECK(refused(R"({"id":1,"op":"move","position_mm":1,"speed_mm_s":1,"sped":2})", fe::xeg_operations()).kind ==
          CommandErrorKind::invalid_field);
    CHECK(refused(R"({"id":1,"op":"trigger","index":64})", fe::xeg_operations()).kind == CommandErrorKind::out_of_range);
    CHECK(refused(R"({"id":1,"op":"trigger","index":1.5})", fe::xeg_operations()).kind == CommandErrorKind::invalid_field);
    CHECK(refused(R"({"id":1,"op":"abs","position":8300001})", fe::excd_operations()).kind == CommandErrorKind::out_of_range);
    CHECK(refused(R"({"id":1,"op":"jog","direction":"up","mode":"inch"})", fe::excd_operations()).kind ==
          CommandErrorKind::out_of_range);
    CHECK(refused(R"({"id":1,"op":"grip","force_pct":10})", fe::wtec_operations()).kind == CommandErrorKind::out_of_range);
    CHECK(refused(R"({"id":1,"op":"clear_alarm"})", r6::r6_operations()).kind == CommandErrorKind::missing_field);
    CHECK(refused(R"({"id":1,"op":"output","board":8,"point":1,"on":true})", r6::r6_operations()).kind ==
          CommandErrorKind::out_of_range);
    CHECK(refused(R"({"id":1,"op":"write_registers","address":70000,"values":[1]})", fe::OperationSet{}).kind ==
          CommandErrorKind::out_of_range);
    CHECK(refused(R"({"id":1,"op":"write_registers","address":1,"values":[]})", fe::OperationSet{}).kind ==
          CommandErrorKind::invalid_field);
    CHECK(refused(R"({"id":1,"op":"write_registers","address":1,"values":[65536]})", fe::OperationSet{}).kind ==
          CommandErrorKind::out_of_range);
}

TEST_CASE("commands: a key given twice in any object is bad_json, whichever value would win") {
    const auto both_ops = refused(R"({"id":10,"op":"stop","op":"reset"})", fe::xeg_operations());
    CHECK(both_ops.kind == fm::CommandErrorKind::bad_json);
    CHECK(both_ops.message.find("'op' appears twice") != std::string::npos);
    CHECK(both_ops.id.is_null());
    CHECK(refused(R"({"id":1,"id":2,"op":"stop"})", fe::xeg_operations()).kind == fm::CommandErrorKind::bad_json);
    CHECK(refused(R"({"id":1,"op":"write_registers","table":"holding","address":1,"values":[1],"values":[2]})",
                  fe::OperationSet{})
              .kind == fm::CommandErrorKind::bad_json);
    CHECK(refused(R"({"id":{"a":1,"a":2},"op":"stop"})", fe::xeg_operations()).kind == fm::CommandErrorKind::bad_json);
    // The same key in two different objects is fine.
    CHECK(refused(R"({"id":1,"op":"stop","x":[{"k":1},{"k":2}]})", fe::xeg_operations()).kind ==
          fm::CommandErrorKind::invalid_field);
    CHECK(requests(R"({"id":1,"op":"stop"})", fe::xeg_operations()).size() == 1);
}

TEST_CASE("commands: what the parser lets through, the device's profile still checks (nothing sent)") {
    fe::RegisterImage image;
    const auto xeg = fe::make_profile(fe::DeviceType::hiwin_xeg, fe::ProfileOptions{});
    // 70 mm is beyond every XEG stroke (64 mm at most): 0x03 before anything is sent.
    const auto far = requests(R"({"id":1,"op":"move","position_mm":70,"speed_mm_s":10})", fe::xeg_operations());
    REQUIRE(far.size() == 1);
    CHECK(xeg->validate(far[0], image) == fp::ExceptionCode::illegal_data_value);
    const auto near = requests(R"({"id":1,"op":"move","position_mm":10,"speed_mm_s":10})", fe::xeg_operations());
    CHECK_FALSE(xeg->validate(near[0], image));
    const auto excd = fe::make_profile(fe::DeviceType::excd203mb, fe::ProfileOptions{});
    // Half of the abs pair: 0x02.
    const auto half = requests(R"({"id":1,"op":"set_register","address":256,"value":1})", fe::excd_operations());
    CHECK(excd->validate(half[0], image) == fp::ExceptionCode::illegal_data_address);
    for (const auto& r : requests(R"({"id":1,"op":"jog","direction":"reverse","mode":"continuous"})", fe::excd_operations())) {
        CHECK_FALSE(excd->validate(r, image));
    }
    const auto wtec = fe::make_profile(fe::DeviceType::wtec_rtu, fe::ProfileOptions{});
    for (const auto& r :
         requests(R"({"id":1,"op":"grip","force_pct":50,"speed_pct":80})", fe::wtec_operations(), init_direction(1))) {
        CHECK_FALSE(wtec->validate(r, image));
    }
    CHECK(fm::command_ops(fe::OperationSet{}) == std::vector<std::string_view>{"set_register", "write_registers"});
}
