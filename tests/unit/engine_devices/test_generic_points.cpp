// Generic Modbus device with points (issue 25): map, write checks, poll plan, fields, alarms.
#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include "engine/points/point_requests.hpp"
#include "engine/profiles/generic_profile.hpp"
#include "support.hpp"
#include "point_builders.hpp"

namespace {

using namespace fbt;
namespace fc = fieldbridge::core;
using fe::Table;
using fp::ExceptionCode;
using std::chrono::milliseconds;
using Regs = std::vector<std::uint16_t>;

using fieldbridge::test::point_def;

/// A thermostat-like device: the example of docs/devices.md.
fc::PointModel thermo_points() {
    fc::PointModel m;
    fc::PointDef temperature = point_def("temperature", Table::input, 0x0000, fc::PointType::float32);
    temperature.unit = "°C";
    m.points.push_back(temperature);
    m.points.push_back(point_def("humidity", Table::input, 0x0002, fc::PointType::uint16));
    m.points.push_back(point_def("energy", Table::input, 0x0010, fc::PointType::int32));
    fc::PointDef setpoint = point_def("setpoint", Table::holding, 0x0100, fc::PointType::int16, true);
    setpoint.scale = 0.1;
    setpoint.min = 5.0;
    setpoint.max = 30.0;
    setpoint.unit = "°C";
    m.points.push_back(setpoint);
    fc::PointDef mode = point_def("mode", Table::holding, 0x0101, fc::PointType::uint16, true);
    mode.labels = {{0, "off"}, {1, "heat"}, {2, "cool"}};
    m.points.push_back(mode);
    fc::PointDef eco = point_def("eco", Table::holding, 0x0102, fc::PointType::boolean, true);
    eco.bit = 4;
    m.points.push_back(eco);
    fc::PointDef lock = point_def("keypad_locked", Table::holding, 0x0102, fc::PointType::boolean, true);
    lock.bit = 0;
    m.points.push_back(lock);
    m.points.push_back(point_def("limit", Table::holding, 0x0200, fc::PointType::float64, true));
    m.points.push_back(point_def("serial", Table::holding, 0x0300, fc::PointType::uint32));
    fc::PointDef name = point_def("model_name", Table::holding, 0x0310, fc::PointType::string);
    name.count = 4;
    m.points.push_back(name);
    m.points.push_back(point_def("relay", Table::coils, 0x0007, fc::PointType::boolean, true));
    m.points.push_back(point_def("status", Table::input, 0x0020, fc::PointType::uint16));
    m.points.back().period = milliseconds{100};
    return m;
}

fe::ProfileOptions thermo_options() {
    fe::ProfileOptions o;
    o.points = thermo_points();
    // A writable raw block over the read-only serial: the point decides.
    o.blocks = {{Table::holding, 0x0300, 4, milliseconds{5000}, true}};
    return o;
}

std::string refusal_of(const fe::ProfileOptions& o) {
    try {
        const fe::GenericProfile g{o};
    } catch (const fe::ProfileError& e) {
        return e.what();
    }
    return "";
}

void feed(const fe::GenericProfile& g, fe::RegisterImage& image, const fp::Request& read, const Regs& values) {
    const auto* regs = std::get_if<fp::ReadRegistersRequest>(&read);
    REQUIRE(regs != nullptr);
    const fe::Reply reply = registers(regs->function, values);
    REQUIRE(g.apply(fe::ModbusPayload{read}, reply, image, t0()).status == fe::ApplyStatus::applied);
}

}  // namespace

TEST_CASE("generic points: the map is the points' registers plus the blocks") {
    const fe::GenericProfile g{thermo_options()};
    const fe::RegisterImage image;
    CHECK_FALSE(g.validate(read_input(0x0000, 3), image));
    CHECK_FALSE(g.validate(read_input(0x0001, 1), image));  // half a float: reads are harmless
    CHECK(g.validate(read_input(0x0000, 4), image) == ExceptionCode::illegal_data_address);  // 0x0003: a hole
    CHECK_FALSE(g.validate(read_holding(0x0100, 3), image));
    CHECK_FALSE(g.validate(read_holding(0x0300, 4), image));  // the block
    CHECK_FALSE(g.validate(read_holding(0x0310, 4), image));
    CHECK(g.validate(read_holding(0x0310, 5), image) == ExceptionCode::illegal_data_address);
    CHECK_FALSE(g.validate(read_bits(fp::fc::read_coils, 7, 1), image));
    CHECK(g.validate(read_bits(fp::fc::read_coils, 6, 2), image) == ExceptionCode::illegal_data_address);
    // Blocks still alone: no points, the map is as before.
    REQUIRE(g.point_units().size() == 11);  // eco and keypad_locked share 0x0102
    const auto shared = std::find_if(g.point_units().begin(), g.point_units().end(),
                                     [](const fe::PointUnit& u) { return u.address == 0x0102; });
    CHECK(shared->points.size() == 2);
}

TEST_CASE("generic points: a TCP write is checked against the point it touches") {
    const fe::GenericProfile g{thermo_options()};
    const fe::RegisterImage image;
    // setpoint: int16 × 0.1, 5-30 °C.
    CHECK_FALSE(g.validate(write_single(0x0100, 215), image));
    CHECK_FALSE(g.validate(write_single(0x0100, 300), image));
    CHECK(g.validate(write_single(0x0100, 301), image) == ExceptionCode::illegal_data_value);
    CHECK(g.validate(write_single(0x0100, 49), image) == ExceptionCode::illegal_data_value);
    CHECK(g.validate(write_single(0x0100, 0xFFFF), image) == ExceptionCode::illegal_data_value);  // -0.1 °C
    // mode: only the enum's codes; several points in one write, each checked.
    CHECK_FALSE(g.validate(write_multiple(0x0100, {215, 2}), image));
    CHECK(g.validate(write_multiple(0x0100, {215, 3}), image) == ExceptionCode::illegal_data_value);
    CHECK(g.validate(write_multiple(0x0100, {400, 1}), image) == ExceptionCode::illegal_data_value);
    // limit: a float64 is written whole (0x02 otherwise, as the EXCD pairs), never NaN.
    CHECK_FALSE(g.validate(write_multiple(0x0200, {0x3FF0, 0, 0, 0}), image));
    CHECK(g.validate(write_multiple(0x0200, {0x3FF0, 0}), image) == ExceptionCode::illegal_data_address);
    CHECK(g.validate(write_multiple(0x0202, {0, 0}), image) == ExceptionCode::illegal_data_address);
    CHECK(g.validate(write_single(0x0201, 0), image) == ExceptionCode::illegal_data_address);
    CHECK(g.validate(write_multiple(0x0200, {0x7FF8, 0, 0, 0}), image) == ExceptionCode::illegal_data_value);
    CHECK(g.validate(write_multiple(0x0200, {0x7FF0, 0, 0, 0}), image) == ExceptionCode::illegal_data_value);
    // serial: read-only, though a writable block covers it; the block's own registers stay writable.
    CHECK(g.validate(write_multiple(0x0300, {0, 1}), image) == ExceptionCode::illegal_data_address);
    CHECK_FALSE(g.validate(write_multiple(0x0302, {0, 1}), image));
    CHECK(g.validate(read_holding(0x0300, 4), image) == std::nullopt);
    // model_name: read-only string.
    CHECK(g.validate(write_multiple(0x0310, {0x4142, 0, 0, 0}), image) == ExceptionCode::illegal_data_address);
    // Bits of one register: written as the register; masked only where every point is a bit.
    CHECK_FALSE(g.validate(write_single(0x0102, 0x0011), image));
    CHECK_FALSE(g.validate(fp::MaskWriteRegisterRequest{0x0102, 0xFFEF, 0x0010}, image));
    CHECK(g.validate(fp::MaskWriteRegisterRequest{0x0100, 0xFFFE, 0x0001}, image) == ExceptionCode::illegal_data_value);
    // FC17's write is checked as well.
    CHECK(g.validate(fp::ReadWriteRegistersRequest{0x0100, 1, 0x0100, {999}}, image) ==
          ExceptionCode::illegal_data_value);
    CHECK_FALSE(g.validate(fp::ReadWriteRegistersRequest{0x0100, 1, 0x0100, {100}}, image));
    // Coils and read-only tables.
    CHECK_FALSE(g.validate(fp::WriteSingleCoilRequest{7, true}, image));
    const auto c = g.classify(write_single(0x0100, 215));
    CHECK(c.write);
    CHECK_FALSE(c.motion);
}

TEST_CASE("generic points: the poll plan merges neighbours across max_gap, each at its period") {
    fe::ProfileOptions o = thermo_options();
    const auto plan_of = [](const fe::ProfileOptions& options) {
        const fe::GenericProfile g{options};
        std::vector<std::string> seen;
        const fe::PollPlan plan = g.poll_plan();
        for (const auto& item : plan.items()) {
            seen.push_back(pdu_hex(item.payload) + " @" +
                           std::to_string(std::chrono::duration_cast<milliseconds>(item.period).count()));
        }
        std::sort(seen.begin(), seen.end());
        return seen;
    };
    // max_gap 8: input 0x0000-0x0002 (float32 + uint16) apart from 0x0010 (gap of 13);
    // holding 0x0100-0x0102 apart from 0x0200; the block at its own period (serial
    // there at 1000 ms too: read as a point); status at 100 ms.
    CHECK(plan_of(o) == std::vector<std::string>{
                            "01 00 07 00 01 @1000",
                            "03 01 00 00 03 @1000",
                            "03 02 00 00 04 @1000",
                            "03 03 00 00 02 @1000",
                            "03 03 00 00 04 @5000",
                            "03 03 10 00 04 @1000",
                            "04 00 00 00 03 @1000",
                            "04 00 10 00 02 @1000",
                            "04 00 20 00 01 @100",
                        });
    // max_gap 16: serial and model_name in one read across 14 registers; the input
    // points too (status stays apart: another period).
    o.points.max_gap = 16;
    CHECK(plan_of(o) == std::vector<std::string>{
                            "01 00 07 00 01 @1000",
                            "03 01 00 00 03 @1000",
                            "03 02 00 00 04 @1000",
                            "03 03 00 00 04 @5000",
                            "03 03 00 00 14 @1000",
                            "04 00 00 00 12 @1000",
                            "04 00 20 00 01 @100",
                        });
    // A gap of 2 (0x0003-0x0004): bridged at the default 8, not at 0.
    o.points.points.push_back(point_def("outdoor", Table::input, 0x0005, fc::PointType::int16));
    o.points.max_gap = 8;
    CHECK(plan_of(o)[6] == "04 00 00 00 06 @1000");
    o.points.max_gap = 0;
    CHECK(plan_of(o)[6] == "04 00 00 00 03 @1000");
    CHECK(plan_of(o)[7] == "04 00 05 00 01 @1000");
}

TEST_CASE("generic points: a merged read stores only the map's registers; refused, it is split at the gap") {
    fe::ProfileOptions o = thermo_options();
    o.points.max_gap = 16;
    const fe::GenericProfile g{o};
    fe::PollPlan plan = g.poll_plan();
    const auto it = std::find_if(plan.items().begin(), plan.items().end(), [](const fe::PollItem& i) {
        return pdu_hex(i.payload) == "04 00 00 00 12";
    });
    REQUIRE(it != plan.items().end());
    CHECK(it->fills == std::vector<fe::RegisterSpan>{{Table::input, 0, 3}, {Table::input, 0x10, 2}});
    fe::RegisterImage image;
    Regs values(0x12, 0x5555);
    feed(g, image, request_of(it->payload), values);
    CHECK(image.value(Table::input, 0x0002) == 0x5555);
    CHECK(image.value(Table::input, 0x0011) == 0x5555);
    CHECK_FALSE(image.value(Table::input, 0x0003));  // a gap: no register of the device
    CHECK_FALSE(image.value(Table::input, 0x000F));

    const auto split = plan.on_block_rejected(it->id);
    REQUIRE(split.size() == 2);
    CHECK(pdu_hex(split[0].payload) == "04 00 00 00 03");
    CHECK(pdu_hex(split[1].payload) == "04 00 10 00 02");
}

TEST_CASE("generic points: fields in engineering units, in the points' order") {
    const fe::GenericProfile g{thermo_options()};
    fe::RegisterImage image;
    CHECK(g.decode_state(image).fields.empty());
    feed(g, image, read_input(0x0000, 3), {0x41AC, 0x0000, 48});
    feed(g, image, read_holding(0x0100, 3), {215, 1, 0x0011});
    feed(g, image, read_holding(0x0310, 4), {0x5448, 0x2D31, 0x0000, 0x0000});
    const fe::DecodedState s = g.decode_state(image);
    std::vector<std::string> names;
    for (const fe::Field& f : s.fields) names.push_back(f.name);
    CHECK(names == std::vector<std::string>{"temperature", "humidity", "setpoint", "mode", "mode_code", "eco",
                                            "keypad_locked", "model_name"});
    CHECK(field<double>(s, "temperature") == 21.5);
    CHECK(s.find("temperature")->unit == "°C");
    CHECK(field<std::int64_t>(s, "humidity") == 48);
    CHECK(field<double>(s, "setpoint") == doctest::Approx(21.5));
    CHECK(field<std::string>(s, "mode") == "heat");
    CHECK(field<std::int64_t>(s, "mode_code") == 1);
    CHECK(field<bool>(s, "eco"));
    CHECK(field<bool>(s, "keypad_locked"));
    CHECK(field<std::string>(s, "model_name") == "TH-1");
    // A code the enum does not name: the code in place of the label.
    feed(g, image, read_holding(0x0101, 1), {9});
    CHECK(field<std::int64_t>(g.decode_state(image), "mode") == 9);
}

TEST_CASE("generic points: enum_other names unknown codes, enum_code: false drops <name>_code, invert, hex") {
    fe::ProfileOptions o;
    fc::PointDef direction = point_def("direction", Table::holding, 0x0000, fc::PointType::uint16);
    direction.labels = {{1, "open"}, {2, "close"}, {0x11, "close"}};  // read-only: two codes alike
    direction.enum_other = "unknown";
    direction.enum_code = false;
    o.points.points.push_back(direction);
    fc::PointDef busy = point_def("busy", Table::holding, 0x0001, fc::PointType::boolean);
    busy.bit = 0;
    busy.invert = true;
    o.points.points.push_back(busy);
    fc::PointDef flag = point_def("flag", Table::holding, 0x0002, fc::PointType::boolean);  // the whole register
    o.points.points.push_back(flag);
    fc::PointDef version = point_def("version", Table::holding, 0x0003, fc::PointType::uint32);
    version.format = fc::PointFormat::hex;
    o.points.points.push_back(version);
    const fe::GenericProfile g{o};
    fe::RegisterImage image;
    feed(g, image, read_holding(0x0000, 5), {0x11, 0, 2, 0x0001, 0x0203});
    fe::DecodedState s = g.decode_state(image);
    std::vector<std::string> names;
    for (const fe::Field& f : s.fields) names.push_back(f.name);
    CHECK(names == std::vector<std::string>{"direction", "busy", "flag", "version"});
    CHECK(field<std::string>(s, "direction") == "close");
    CHECK(field<bool>(s, "busy"));
    CHECK(field<bool>(s, "flag"));
    CHECK(field<std::string>(s, "version") == "0x00010203");
    feed(g, image, read_holding(0x0000, 3), {7, 1, 0});
    s = g.decode_state(image);
    CHECK(field<std::string>(s, "direction") == "unknown");
    CHECK_FALSE(field<bool>(s, "busy"));
    CHECK_FALSE(field<bool>(s, "flag"));
}

TEST_CASE("generic points: alarms with hysteresis, bit and enum conditions") {
    fe::ProfileOptions o = thermo_options();
    fc::AlarmRule hot;
    hot.name = "too_hot";
    hot.point = "temperature";
    hot.condition = fc::AlarmCondition::above;
    hot.threshold = 30;
    hot.hysteresis = 2;
    hot.severity = fc::AlarmSeverity::critical;
    fc::AlarmRule fault;
    fault.name = "sensor_fault";
    fault.point = "status";
    fault.condition = fc::AlarmCondition::bit;
    fault.bit = 2;
    fault.text = "Sensor fault: check the probe wiring";
    fc::AlarmRule off;
    off.name = "heating_off";
    off.point = "mode";
    off.condition = fc::AlarmCondition::equals;
    off.threshold = 0;
    o.points.alarms = {hot, fault, off};
    const fe::GenericProfile g{o};
    fe::RegisterImage image;
    CHECK(g.alarms(image).empty());  // nothing read yet
    const auto temperature = [&](std::uint16_t high) { feed(g, image, read_input(0x0000, 2), {high, 0x0000}); };
    const auto codes = [&g, &image] {
        std::vector<std::string> out;
        for (const fe::Alarm& a : g.alarms(image)) out.push_back(a.code);
        return out;
    };
    temperature(0x41F0);  // 30.0: not above
    CHECK(codes().empty());
    temperature(0x41F8);  // 31.0
    const std::vector<fe::Alarm> raised = g.alarms(image);
    REQUIRE(raised.size() == 1);
    CHECK(raised[0] == fe::Alarm{"too_hot", "temperature above 30 °C", fe::Severity::critical, "point temperature"});
    temperature(0x41E8);  // 29.0: inside the hysteresis, still raised
    CHECK(codes() == std::vector<std::string>{"too_hot"});
    temperature(0x41E0);  // 28.0: cleared
    CHECK(codes().empty());
    temperature(0x41E8);  // 29.0 again: not raised from below
    CHECK(codes().empty());

    feed(g, image, read_input(0x0020, 1), {0x0004});
    feed(g, image, read_holding(0x0100, 3), {215, 0, 0});
    const std::vector<fe::Alarm> more = g.alarms(image);
    REQUIRE(more.size() == 2);
    CHECK(more[0] == fe::Alarm{"sensor_fault", "Sensor fault: check the probe wiring", fe::Severity::warning,
                               "point status"});
    CHECK(more[1].text == "mode is off");
    feed(g, image, read_input(0x0020, 1), {0x0003});
    feed(g, image, read_holding(0x0101, 1), {1});
    CHECK(codes().empty());
}

TEST_CASE("generic points: a model the map cannot hold is refused with a reason") {
    fe::ProfileOptions o;
    o.points = thermo_points();
    CHECK(refusal_of(o).empty());  // points alone are enough
    o.points.points.push_back(point_def("overlap", Table::input, 0x0001, fc::PointType::uint16));
    CHECK(refusal_of(o).find("point 'temperature' (input 0x0000) and point 'overlap' (input 0x0001) overlap") !=
          std::string::npos);
    o.points = thermo_points();
    o.points.points.push_back(point_def("wrong", Table::input, 0x0050, fc::PointType::uint16, true));
    CHECK(refusal_of(o).find("point 'wrong' (input 0x0050) is marked writable") != std::string::npos);
    o.points = thermo_points();
    o.points.points.push_back(point_def("tail", Table::holding, 0xFFFF, fc::PointType::uint32));
    CHECK(refusal_of(o).find("runs past address 0xFFFF") != std::string::npos);
    o.points = thermo_points();
    o.points.points.push_back(point_def("empty", Table::holding, 0x0400, fc::PointType::string));
    CHECK(refusal_of(o).find("check its `count`") != std::string::npos);
    o.points = thermo_points();
    fc::AlarmRule orphan;
    orphan.name = "orphan";
    orphan.point = "pressure";
    o.points.alarms.push_back(orphan);
    CHECK(refusal_of(o).find("alarm 'orphan' is on point 'pressure'") != std::string::npos);
    o.points = {};
    CHECK(refusal_of(o).find("no register blocks and no points") != std::string::npos);
}

TEST_CASE("generic points: what the point write requests send passes the profile's own checks") {
    namespace pts = fieldbridge::engine::points;
    const fe::GenericProfile g{thermo_options()};
    fe::RegisterImage image;
    const std::vector<pts::PointWrite> writes{{"setpoint", 30.0},          {"setpoint", std::int64_t{5}},
                                              {"mode", std::string{"cool"}}, {"eco", true},
                                              {"keypad_locked", false},      {"limit", -1.5e300},
                                              {"relay", false}};
    const pts::PointRequests r = pts::write_requests(g.options().points, writes);
    REQUIRE(r.ok());
    REQUIRE(r.requests.size() == writes.size());
    for (const fp::Request& q : r.requests) {
        INFO(hex(fp::encode_request(q)));
        CHECK_FALSE(g.validate(q, image));
    }
    // And a fresh read of points is a read the map allows.
    const std::vector<std::string> names{"temperature", "humidity", "energy", "model_name", "relay", "status"};
    const pts::PointRequests reads = pts::read_requests(g.options().points, names);
    REQUIRE(reads.ok());
    for (const fp::Request& q : reads.requests) {
        CHECK_FALSE(g.validate(q, image));
    }
}
