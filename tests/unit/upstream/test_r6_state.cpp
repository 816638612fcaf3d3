#include <doctest/doctest.h>

#include <vector>

#include "northbound/upstream/r6_state.hpp"

using namespace fieldbridge;
using namespace fieldbridge::northbound::upstream;
using engine::Table;

namespace {
engine::TimePoint now() { return engine::Clock::now(); }

template <typename T>
T field(const engine::DecodedState& s, std::string_view name) {
    const engine::Field* f = s.find(name);
    REQUIRE_MESSAGE(f != nullptr, "no field " << name);
    REQUIRE(std::holds_alternative<T>(f->value));
    return std::get<T>(f->value);
}
}  // namespace

TEST_CASE("a poll cycle reads mode, axes as many as there are, world, alarm and cycles, move state") {
    engine::RegisterImage image;
    const auto read = [&](std::size_t step) { return r6_poll_read(step, image); };
    REQUIRE(read(0));
    CHECK(read(0)->address == 0x0889);
    CHECK(read(0)->count == 1);
    CHECK(read(1)->address == 0x08DB);
    CHECK_FALSE(read(2));  // axis count unknown
    CHECK(read(3)->address == 0x091C);
    CHECK(read(3)->count == 16);
    CHECK(read(4)->address == 0x095C);
    CHECK(read(4)->count == 9);
    CHECK(read(5)->address == 0x09A6);
    CHECK(read(5)->count == 2);
    CHECK_FALSE(read(r6_poll_steps));
    const std::vector<std::uint16_t> six{6};
    image.update(Table::holding, 0x08DB, six, now());
    REQUIRE(read(2));
    CHECK(read(2)->address == 0x08DC);
    CHECK(read(2)->count == 12);
    const std::vector<std::uint16_t> none{0};
    image.update(Table::holding, 0x08DB, none, now());
    CHECK_FALSE(read(2));
    const std::vector<std::uint16_t> too_many{12};
    image.update(Table::holding, 0x08DB, too_many, now());
    CHECK(read(2)->count == 16);  // at most 8 axes (seed 004 3.1.8)
}

TEST_CASE("decoding: signed 32-bit x1000 high word first, 64-bit cycle times, flags") {
    engine::RegisterImage image;
    CHECK(decode_r6_state(image).fields.empty());
    const auto put = [&](std::uint16_t address, std::vector<std::uint16_t> words) {
        image.update(Table::holding, address, words, now());
    };
    put(0x0889, {2});
    put(0x08DB, {2});
    put(0x08DC, {0x0000, 0x2710, 0xFFFF, 0xFC18});  // 10.000 deg, -1.000 deg
    put(0x091C, {0x0001, 0x86A0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xFFFF, 0xFFFF});
    put(0x095C, {0x0325, 0x0000, 0x0001, 0x0000, 0x0002, 0, 0, 0, 0x1770});
    put(0x09A6, {1, 0});
    const engine::DecodedState s = decode_r6_state(image);
    CHECK(field<std::int64_t>(s, "mode") == 2);
    CHECK(field<std::string>(s, "mode_name") == "auto");
    CHECK(field<std::int64_t>(s, "alarm") == 0x0325);
    CHECK(field<bool>(s, "alarm_active"));
    CHECK(field<bool>(s, "moving"));
    CHECK_FALSE(field<bool>(s, "origin_set"));
    CHECK(field<std::int64_t>(s, "axis_count") == 2);
    // Spec §6: arrays, J1 first / X Y Z U V W M7 M8.
    CHECK(field<std::vector<double>>(s, "axes_deg") == std::vector<double>{10.0, -1.0});
    const auto world = field<std::vector<double>>(s, "world_mm");
    REQUIRE(world.size() == 8);
    CHECK(world[0] == doctest::Approx(100.0));
    CHECK(world[7] == doctest::Approx(-0.001));
    CHECK(s.find("world_mm")->unit == "mm");
    CHECK(s.find("axes_deg")->unit == "deg");
    CHECK(s.find("axis_1") == nullptr);  // no flat fields
    CHECK(s.find("world_x") == nullptr);
    CHECK(field<std::int64_t>(s, "cycle_time") == 0x0000000100000002LL);
    CHECK(field<std::int64_t>(s, "last_cycle_time") == 6000);
    const auto alarms = r6_alarms(image);
    REQUIRE(alarms.size() == 1);
    CHECK(alarms[0].code == "r6_alarm_805");
    put(0x095C, {0});
    CHECK(r6_alarms(image).empty());
    put(0x0889, {3});
    CHECK(field<std::string>(decode_r6_state(image), "mode_name") == "configuration");
}
