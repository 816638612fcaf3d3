// The profiles' MQTT operations (engine/profiles/operations.hpp): each operation's
// fields and the registers it writes, against the manuals' tables and example frames
// (tests/vectors/vectors.yaml); what the profile sends on the line for them.
#include <doctest/doctest.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/profiles/excd_profile.hpp"
#include "engine/profiles/operations.hpp"
#include "engine/profiles/profile_factory.hpp"
#include "engine/profiles/wtec_common.hpp"
#include "engine/profiles/xeg_profile.hpp"
#include "support.hpp"

using namespace fbt;

namespace {

using Rs = std::vector<fp::Request>;

const fe::Operation& operation(const fe::OperationSet& set, std::string_view name) {
    const fe::Operation* op = set.find(name);
    REQUIRE_MESSAGE(op != nullptr, "no op " << name << " in " << set.name);
    return *op;
}

/// The requests of @p name with @p args (fails the test when the op refuses).
Rs writes(const fe::OperationSet& set, std::string_view name, const fe::OperationArgs& args = {},
          fe::RegisterValues registers = {}) {
    fe::OperationWrites w = operation(set, name).writes(args, registers);
    REQUIRE(std::holds_alternative<Rs>(w));
    return std::get<Rs>(std::move(w));
}

fe::OperationArgs args(std::initializer_list<std::pair<std::string_view, fe::ArgumentValue>> values) {
    fe::OperationArgs a;
    for (const auto& [name, value] : values) a.set(name, value);
    return a;
}

/// "name:kind[min..max]" or "name:choice[a|b]", "?" after optional ones: the fields
/// of an op as docs/mqtt.md lists them.
std::vector<std::string> field_specs(const fe::OperationSet& set, std::string_view name) {
    std::vector<std::string> out;
    const auto number = [](double v) {
        std::string text = std::to_string(v);
        text.erase(text.find_last_not_of('0') + 1);
        if (text.back() == '.') text.pop_back();
        return text;
    };
    for (const fe::OperationField& f : operation(set, name).fields) {
        std::string spec(f.name);
        if (const auto* n = std::get_if<fe::NumberField>(&f.type)) {
            spec += ":number[" + number(n->min) + ".." + number(n->max) + "]";
        } else if (const auto* i = std::get_if<fe::IntegerField>(&f.type)) {
            spec += ":integer[" + std::to_string(i->min) + ".." + std::to_string(i->max) + "]";
        } else if (const auto* c = std::get_if<fe::ChoiceField>(&f.type)) {
            spec += ":choice[";
            for (std::size_t k = 0; k < c->options.size(); ++k) spec += (k ? "|" : "") + std::string(c->options[k]);
            spec += "]";
        } else {
            spec += ":boolean";
        }
        if (f.optional) spec += "?";
        out.push_back(spec);
    }
    return out;
}

std::vector<std::string_view> names(const fe::OperationSet& set) {
    std::vector<std::string_view> out;
    for (const fe::Operation& op : set.operations) out.push_back(op.name);
    return out;
}

/// The PDU of the manual's example request @p what (vectors.yaml): address and CRC cut.
std::string manual_pdu(std::string_view what) {
    const auto& all = fieldbridge::test::all_vectors();
    const auto it = std::find_if(all.begin(), all.end(), [&](const auto& v) { return v.what == what; });
    REQUIRE_MESSAGE(it != all.end(), "no vector " << what);
    const fp::Bytes frame = fieldbridge::test::parse_hex(it->request);
    return hex(fp::ByteView(frame).subspan(1, frame.size() - 3));
}

/// What @p profile sends on the line for @p requests, each validated first.
std::vector<std::string> on_line(const fe::DeviceProfile& profile, const Rs& requests,
                                 const fe::RegisterImage& image = {}) {
    std::vector<std::string> out;
    for (const fp::Request& r : requests) {
        CHECK_FALSE(profile.validate(r, image));
        for (const fe::Payload& p : profile.to_line(r, image)) out.push_back(pdu_hex(p));
    }
    return out;
}

fe::ProfileOptions options() {
    fe::ProfileOptions o;
    o.wtec_stroke = 1000;
    o.blocks = {{fe::Table::holding, 0, 1, std::chrono::milliseconds{100}, false}};
    return o;
}

}  // namespace

TEST_CASE("operations: each profile publishes its type's set; wtec-rtu and wtec-ascii share one") {
    const auto set_of = [](fe::DeviceType type) { return fe::make_profile(type, options())->operations(); };
    CHECK(set_of(fe::DeviceType::hiwin_xeg).name == "xeg");
    CHECK(set_of(fe::DeviceType::excd203mb).name == "excd");
    CHECK(set_of(fe::DeviceType::wtec_rtu).name == "wtec");
    CHECK(set_of(fe::DeviceType::wtec_ascii).name == "wtec");
    CHECK(set_of(fe::DeviceType::wtec_rtu).operations.data() == set_of(fe::DeviceType::wtec_ascii).operations.data());
    // A generic device: none of its own (the raw register ops are the MQTT side's).
    CHECK(set_of(fe::DeviceType::modbus).name == "generic");
    CHECK(set_of(fe::DeviceType::modbus).operations.empty());
    // Static storage: the set outlives the profile that published it.
    const fe::OperationSet kept = set_of(fe::DeviceType::hiwin_xeg);
    CHECK(kept.operations.data() == fe::xeg_operations().operations.data());
    CHECK(kept.find("move") != nullptr);
    CHECK(kept.find("abs") == nullptr);
}

TEST_CASE("operations: hiwin-xeg fields (seed 001 section 3.4)") {
    const auto xeg = fe::xeg_operations();
    CHECK(names(xeg) == std::vector<std::string_view>{"reset", "stop", "move", "expert", "trigger"});
    CHECK(field_specs(xeg, "reset").empty());
    CHECK(field_specs(xeg, "stop").empty());
    // 0.01 mm registers: 655.35 is the most one holds; the model's stroke is the profile's check.
    CHECK(field_specs(xeg, "move") == std::vector<std::string>{"position_mm:number[0..655.35]",
                                                               "speed_mm_s:number[0..655.35]"});
    CHECK(field_specs(xeg, "expert") ==
          std::vector<std::string>{"direction:integer[0..1]", "stroke_mm:number[0..655.35]",
                                   "speed_mm_s:number[0..655.35]", "holding_stroke_mm:number[0..655.35]",
                                   "holding_speed_mm_s:number[0..655.35]", "force_pct:integer[0..100]"});
    CHECK(field_specs(xeg, "trigger") == std::vector<std::string>{"index:integer[1..63]"});
}

TEST_CASE("operations: hiwin-xeg writes, and the manual's frames on the line (seed 001 3.4, Appendix 1)") {
    const auto xeg = fe::xeg_operations();
    CHECK(writes(xeg, "reset") == Rs{write_single(0x0610, 1)});
    CHECK(writes(xeg, "stop") == Rs{write_single(0x0620, 1)});
    CHECK(writes(xeg, "trigger", args({{"index", std::int64_t{10}}})) == Rs{write_single(0x0601, 10)});
    // 0.01 mm units, rounded: 17.505 mm is 1751 (not 1750 by truncation).
    CHECK(writes(xeg, "move", args({{"position_mm", 17.505}, {"speed_mm_s", 20.0}})) ==
          Rs{write_multiple(0x0630, {1751, 2000, 1})});

    const auto profile = fe::make_profile(fe::DeviceType::hiwin_xeg, options());
    // The controller takes FC16 only: reset goes out as the manual's one-register FC16.
    CHECK(on_line(*profile, writes(xeg, "reset")) == std::vector<std::string>{manual_pdu("write reset 0x0610=1")});
    CHECK(on_line(*profile, writes(xeg, "expert",
                                   args({{"direction", std::int64_t{0}},
                                         {"stroke_mm", 10.0},
                                         {"speed_mm_s", 80.0},
                                         {"holding_stroke_mm", 5.0},
                                         {"holding_speed_mm_s", 20.0},
                                         {"force_pct", std::int64_t{100}}}))) ==
          std::vector<std::string>{manual_pdu("write Expert 0x0640-0x0646: dir 0, move 10.00mm, 80.00mm/s, hold "
                                              "5.00mm, 20.00mm/s, 100%, flag 1")});
    CHECK(on_line(*profile, writes(xeg, "move", args({{"position_mm", 32.0}, {"speed_mm_s", 80.0}}))) ==
          std::vector<std::string>{manual_pdu("broadcast Move 0x0630-0x0632: 32.00mm, 80.00mm/s, flag 1 (no reply)")});
}

TEST_CASE("operations: excd203mb fields and writes (seed 002 \"運轉指令\", jog range)") {
    const auto excd = fe::excd_operations();
    CHECK(names(excd) == std::vector<std::string_view>{"abs", "rel", "home", "stop", "jog", "jog_stop"});
    CHECK(field_specs(excd, "abs") == std::vector<std::string>{"position:integer[-8300000..8300000]"});
    CHECK(field_specs(excd, "rel") == std::vector<std::string>{"distance:integer[-8300000..8300000]"});
    CHECK(field_specs(excd, "stop") == std::vector<std::string>{"immediate:boolean?"});
    CHECK(field_specs(excd, "jog") ==
          std::vector<std::string>{"direction:choice[forward|reverse]", "mode:choice[inch|continuous]"});

    // 32-bit pairs high word first (the northbound view).
    CHECK(writes(excd, "abs", args({{"position", std::int64_t{800000}}})) == Rs{write_multiple(0x0100, {0x000C, 0x3500})});
    CHECK(writes(excd, "rel", args({{"distance", std::int64_t{-1}}})) == Rs{write_multiple(0x0104, {0xFFFF, 0xFFFF})});
    CHECK(writes(excd, "home") == Rs{write_single(0x0107, 0)});
    CHECK(writes(excd, "stop") == Rs{write_single(0x0108, 0)});
    CHECK(writes(excd, "stop", args({{"immediate", false}})) == Rs{write_single(0x0108, 0)});
    CHECK(writes(excd, "stop", args({{"immediate", true}})) == Rs{write_single(0x0109, 0)});
    CHECK(writes(excd, "jog_stop") == Rs{write_single(0x010C, 0)});
    // Jog: +1 / -1 one step, or the ends of the range 0x007EA5E0 / 0xFF815A20 (continuous).
    const auto jog = [&](const char* direction, const char* mode) {
        return writes(excd, "jog", args({{"direction", std::string(direction)}, {"mode", std::string(mode)}}));
    };
    CHECK(jog("forward", "inch") == Rs{write_multiple(0x010A, {0x0000, 0x0001})});
    CHECK(jog("reverse", "inch") == Rs{write_multiple(0x010A, {0xFFFF, 0xFFFF})});
    CHECK(jog("forward", "continuous") == Rs{write_multiple(0x010A, {0x007E, 0xA5E0})});
    CHECK(jog("reverse", "continuous") == Rs{write_multiple(0x010A, {0xFF81, 0x5A20})});

    // Every one the profile accepts, and a low-first device gets the words turned round.
    const auto profile = fe::make_profile(fe::DeviceType::excd203mb, options());
    CHECK(on_line(*profile, jog("reverse", "continuous")) == std::vector<std::string>{"10 01 0A 00 02 04 FF 81 5A 20"});
    fe::ProfileOptions low = options();
    low.word_order = fe::WordOrder::low_first;
    const auto low_first = fe::make_profile(fe::DeviceType::excd203mb, low);
    CHECK(on_line(*low_first, jog("reverse", "continuous")) ==
          std::vector<std::string>{"10 01 0A 00 02 04 5A 20 FF 81"});
    for (const char* op : {"home", "stop", "jog_stop"}) {
        CHECK(on_line(*profile, writes(excd, op)).size() == 1);
    }
}

TEST_CASE("operations: wtec fields and writes on the uniform map (seed 003 tables 2.2-2.12)") {
    const auto wtec = fe::wtec_operations();
    CHECK(names(wtec) ==
          std::vector<std::string_view>{"init", "grip", "release", "position", "force", "speed", "estop"});
    CHECK(field_specs(wtec, "grip") ==
          std::vector<std::string>{"force_pct:integer[20..100]?", "speed_pct:integer[1..100]?"});
    CHECK(field_specs(wtec, "release") == field_specs(wtec, "grip"));
    CHECK(field_specs(wtec, "position") == std::vector<std::string>{"percent:integer[0..100]"});
    CHECK(field_specs(wtec, "force") == std::vector<std::string>{"percent:integer[20..100]"});
    CHECK(field_specs(wtec, "speed") == std::vector<std::string>{"percent:integer[1..100]"});

    const auto profile = fe::make_profile(fe::DeviceType::wtec_rtu, options());
    const auto percent = [](std::int64_t p) { return args({{"percent", p}}); };
    CHECK(on_line(*profile, writes(wtec, "init")) == std::vector<std::string>{manual_pdu("initialize (home) 0x0100=1")});
    CHECK(on_line(*profile, writes(wtec, "force", percent(80))) ==
          std::vector<std::string>{manual_pdu("force 0x0103=80%")});
    CHECK(on_line(*profile, writes(wtec, "speed", percent(50))) ==
          std::vector<std::string>{manual_pdu("speed 0x0104=50%")});
    CHECK(on_line(*profile, writes(wtec, "position", percent(50))) ==
          std::vector<std::string>{manual_pdu("position 0x0105=50")});
    CHECK(on_line(*profile, writes(wtec, "estop")) ==
          std::vector<std::string>{manual_pdu("emergency stop 0x0102=1")});
}

TEST_CASE("operations: wtec grip / release follow the init direction (0x0300, seed 003 table 2.9)") {
    const auto wtec = fe::wtec_operations();
    const std::vector<fe::RegisterValue> open_home{{fe::Table::holding, 0x0300, 1}};
    const std::vector<fe::RegisterValue> closed_home{{fe::Table::holding, 0x0300, 2}};
    CHECK(writes(wtec, "grip", {}, open_home) == Rs{write_single(0x0105, 100)});
    CHECK(writes(wtec, "release", {}, open_home) == Rs{write_single(0x0105, 0)});
    CHECK(writes(wtec, "grip", {}, closed_home) == Rs{write_single(0x0105, 0)});
    CHECK(writes(wtec, "release", {}, closed_home) == Rs{write_single(0x0105, 100)});
    // Force, then speed, then the move.
    CHECK(writes(wtec, "grip", args({{"speed_pct", std::int64_t{30}}, {"force_pct", std::int64_t{50}}}), open_home) ==
          Rs{write_single(0x0103, 50), write_single(0x0104, 30), write_single(0x0105, 100)});

    // Unknown direction (not read, another table, a value that is no direction): refused.
    const std::vector<fe::RegisterValue> input_table{{fe::Table::input, 0x0300, 1}};
    const std::vector<fe::RegisterValue> odd{{fe::Table::holding, 0x0300, 7}};
    for (const auto& registers : {std::vector<fe::RegisterValue>{}, input_table, odd}) {
        const fe::OperationWrites w = operation(wtec, "release").writes({}, registers);
        const auto* unknown = std::get_if<fe::StateUnknown>(&w);
        REQUIRE(unknown != nullptr);
        CHECK(unknown->message.find("op 'release' needs the gripper's init direction (holding 0x0300)") == 0);
        CHECK(unknown->message.find("nothing was sent") != std::string::npos);
    }
    CHECK(std::get<fe::StateUnknown>(operation(wtec, "grip").writes({}, odd)).message.find("reads 7") !=
          std::string::npos);
}

TEST_CASE("operations: reading a field the table does not declare, or as another type, is a bug") {
    const fe::OperationArgs a = args({{"percent", std::int64_t{5}}});
    CHECK(a.has("percent"));
    CHECK_FALSE(a.has("force_pct"));
    CHECK(a.integer("percent") == 5);
    CHECK_THROWS_AS((void)a.number("percent"), std::logic_error);
    CHECK_THROWS_AS((void)a.integer("force_pct"), std::logic_error);
}

TEST_CASE("operations: every op of every table writes with the fields it declares, at both ends of each range") {
    // A value of each declared field (optional ones given too), the lowest or the
    // highest the spec allows: a writes function that reads an undeclared field, or
    // one as another type, throws; each must give at least one request the profile
    // accepts.
    const auto sample = [](const fe::Operation& op, bool high) {
        fe::OperationArgs a;
        for (const fe::OperationField& f : op.fields) {
            if (const auto* n = std::get_if<fe::NumberField>(&f.type)) {
                a.set(f.name, high ? n->max : n->min);
            } else if (const auto* i = std::get_if<fe::IntegerField>(&f.type)) {
                a.set(f.name, high ? i->max : i->min);
            } else if (const auto* c = std::get_if<fe::ChoiceField>(&f.type)) {
                a.set(f.name, std::string(high ? c->options.back() : c->options.front()));
            } else {
                a.set(f.name, high);
            }
        }
        return a;
    };
    const std::vector<fe::RegisterValue> direction_known{{fe::Table::holding, 0x0300, 1}};
    const struct {
        fe::OperationSet set;
        fe::DeviceType type;
    } tables[] = {{fe::xeg_operations(), fe::DeviceType::hiwin_xeg},
                  {fe::excd_operations(), fe::DeviceType::excd203mb},
                  {fe::wtec_operations(), fe::DeviceType::wtec_rtu},
                  {fe::wtec_operations(), fe::DeviceType::wtec_ascii}};
    for (const auto& t : tables) {
        const auto profile = fe::make_profile(t.type, options());
        for (const fe::Operation& op : t.set.operations) {
            for (const bool high : {false, true}) {
                const std::string label =
                    std::string(fe::to_string(t.type)) + " " + std::string(op.name) + (high ? " high" : " low");
                INFO(label);
                const bool has_writes = op.writes != nullptr;
                REQUIRE(has_writes);
                fe::OperationWrites w;
                REQUIRE_NOTHROW(w = op.writes(sample(op, high), direction_known));
                REQUIRE(std::holds_alternative<Rs>(w));
                CHECK_FALSE(std::get<Rs>(w).empty());
                for (const fp::Request& r : std::get<Rs>(w)) {
                    // The XEG's fields are wider than any model (0.01 mm registers to
                    // 655.35 mm, force 0-100 %): the profile refuses what the model
                    // cannot do with 0x03 (§3.4.2 table), nothing else.
                    const auto refused = profile->validate(r, fe::RegisterImage{});
                    if (t.type == fe::DeviceType::hiwin_xeg) {
                        CHECK((!refused || *refused == fp::ExceptionCode::illegal_data_value));
                    } else if (t.type == fe::DeviceType::wtec_ascii) {
                        // Force and speed translate with R / N values not read yet: 0x0B.
                        CHECK((!refused || *refused == fp::ExceptionCode::gateway_target_failed));
                    } else {
                        CHECK_FALSE(refused);
                    }
                }
            }
        }
    }
}

TEST_CASE("operations: helpers") {
    CHECK(fe::high_word_first(1600000) == std::vector<std::uint16_t>{0x0018, 0x6A00});
    CHECK(fe::high_word_first(-8300000) == std::vector<std::uint16_t>{0xFF81, 0x5A20});
    CHECK(fe::hundredths(0.0) == 0);
    CHECK(fe::hundredths(655.35) == 65535);
    CHECK(fe::hundredths(0.004) == 0);
    CHECK(fe::hundredths(0.005) == 1);
    const std::vector<fe::RegisterValue> regs{{fe::Table::input, 7, 1}, {fe::Table::holding, 7, 2}};
    CHECK(fe::register_value(regs, fe::Table::holding, 7) == 2);
    CHECK(fe::register_value(regs, fe::Table::input, 7) == 1);
    CHECK_FALSE(fe::register_value(regs, fe::Table::coils, 7));
}
