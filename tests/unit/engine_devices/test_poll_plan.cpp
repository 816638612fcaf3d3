// Rule 8: merging adjacent polls, never across a hole; splitting on exception 0x02.
#include <doctest/doctest.h>

#include <chrono>
#include <vector>

#include "engine/profiles/poll_plan.hpp"
#include "engine/profiles/register_map.hpp"
#include "support.hpp"

namespace {

using namespace fbt;
using fe::PollClass;
using fe::PollPlan;
using fe::PollUnit;
using fe::RegisterSpan;
using fe::Table;
using std::chrono::milliseconds;

PollUnit unit(std::uint16_t address, std::uint16_t count, PollClass c = PollClass::fast,
              fe::Duration period = milliseconds{50}, Table table = Table::holding) {
    return PollUnit{RegisterSpan{table, address, count}, c, period, false, 0};
}

fp::ReadRegistersRequest read_of(const fe::PollItem& item) {
    return std::get<fp::ReadRegistersRequest>(request_of(item.payload));
}

}  // namespace

TEST_CASE("poll plan: touching units at the same period merge into one block read") {
    const auto items = fe::merge_units({unit(0x0200, 1), unit(0x0201, 2), unit(0x0203, 1)});
    REQUIRE(items.size() == 1);
    CHECK(read_of(items[0]) == fp::ReadRegistersRequest{fp::fc::read_holding_registers, 0x0200, 4});
    CHECK(items[0].fills == std::vector<RegisterSpan>{{Table::holding, 0x0200, 4}});
    CHECK(items[0].units.size() == 3);
}

TEST_CASE("poll plan: a gap is never bridged; periods, classes and tables are not mixed") {
    const auto items = fe::merge_units({
        unit(0x0200, 1),
        unit(0x0202, 1),                                         // gap at 0x0201
        unit(0x0203, 1, PollClass::slow, milliseconds{1000}),    // touches, other period
        unit(0x0204, 1, PollClass::fast, milliseconds{50}, Table::input),  // other table
    });
    REQUIRE(items.size() == 4);
    for (const auto& item : items) {
        CHECK(item.units.size() == 1);
    }
}

TEST_CASE("poll plan: custom periods merge only when equal") {
    const auto items = fe::merge_units({unit(0, 10, PollClass::custom, milliseconds{100}),
                                        unit(10, 10, PollClass::custom, milliseconds{100}),
                                        unit(20, 10, PollClass::custom, milliseconds{200})});
    REQUIRE(items.size() == 2);
    CHECK(read_of(items[0]).count == 20);
    CHECK(items[0].period == milliseconds{100});
    CHECK(read_of(items[1]).address == 20);
}

TEST_CASE("poll plan: a block never exceeds 125 registers or 2000 bits") {
    std::vector<PollUnit> units;
    for (std::uint16_t a = 0; a < 300; ++a) units.push_back(unit(a, 1));
    const auto items = fe::merge_units(units);
    REQUIRE(items.size() == 3);
    CHECK(read_of(items[0]).count == 125);
    CHECK(read_of(items[1]).count == 125);
    CHECK(read_of(items[2]).count == 50);

    std::vector<PollUnit> bits;
    for (std::uint16_t a = 0; a < 2100; ++a) bits.push_back(unit(a, 1, PollClass::fast, milliseconds{50}, Table::coils));
    const auto bit_items = fe::merge_units(bits);
    REQUIRE(bit_items.size() == 2);
    CHECK(std::get<fp::ReadBitsRequest>(request_of(bit_items[0].payload)) ==
          fp::ReadBitsRequest{fp::fc::read_coils, 0, 2000});
}

TEST_CASE("poll plan: a pair is one unit and is never cut when merging or splitting") {
    fe::RegisterDef pair;
    pair.address = 0x0201;
    pair.width = 2;
    pair.name = "rabs";
    fe::RegisterDef single;
    single.address = 0x0200;
    single.name = "rms";
    fe::RegisterDef after;
    after.address = 0x0203;
    after.count = 2;
    after.name = "rin/rout";
    const fe::RegisterMap map({single, pair, after});
    const auto units = map.poll_units(RegisterSpan{Table::holding, 0x0200, 5}, PollClass::fast, milliseconds{50}, false);
    REQUIRE(units.size() == 4);  // 0x0200, pair 0x0201-0x0202, 0x0203, 0x0204
    CHECK(units[1].span == RegisterSpan{Table::holding, 0x0201, 2});

    PollPlan plan{fe::merge_units(units)};
    REQUIRE(plan.items().size() == 1);
    const std::uint32_t id = plan.items()[0].id;
    const auto halves = plan.on_block_rejected(id);
    REQUIRE(halves.size() == 2);
    // Halves at a unit boundary: [0x0200, pair] and [0x0203, 0x0204].
    CHECK(read_of(halves[0]) == fp::ReadRegistersRequest{fp::fc::read_holding_registers, 0x0200, 3});
    CHECK(read_of(halves[1]) == fp::ReadRegistersRequest{fp::fc::read_holding_registers, 0x0203, 2});
}

TEST_CASE("poll plan: split on 0x02 down to single units, remembered; a lone unit rejected is dropped") {
    std::vector<PollUnit> units;
    for (std::uint16_t a = 0; a < 4; ++a) units.push_back(unit(a, 1));
    PollPlan plan{fe::merge_units(units)};
    REQUIRE(plan.items().size() == 1);
    const std::uint32_t first = plan.items()[0].id;

    auto halves = plan.on_block_rejected(first);
    REQUIRE(halves.size() == 2);
    CHECK(plan.find(first) == nullptr);
    CHECK(plan.items().size() == 2);
    CHECK(halves[0].id != halves[1].id);
    CHECK(halves[0].id != first);
    CHECK(plan.find(halves[1].id) != nullptr);

    // The half holding the bad register is rejected again: singles.
    auto quarters = plan.on_block_rejected(halves[1].id);
    REQUIRE(quarters.size() == 2);
    CHECK(read_of(quarters[0]).address == 2);
    CHECK(read_of(quarters[1]).address == 3);
    CHECK(plan.items().size() == 3);

    // A single register the device refuses: gone for good.
    CHECK(plan.on_block_rejected(quarters[1].id).empty());
    CHECK(plan.items().size() == 2);
    CHECK(plan.rejected().size() == 1);
    CHECK(plan.rejected()[0] == RegisterSpan{Table::holding, 3, 1});
    // The plan keeps the split: the remaining items are 0-1 and 2.
    CHECK(read_of(plan.items()[0]) == fp::ReadRegistersRequest{fp::fc::read_holding_registers, 0, 2});
    CHECK(read_of(plan.items()[1]) == fp::ReadRegistersRequest{fp::fc::read_holding_registers, 2, 1});

    CHECK(plan.on_block_rejected(9999).empty());  // unknown id
}

namespace {

PollUnit bridging(std::uint16_t address, std::uint16_t count, std::uint16_t max_gap) {
    return PollUnit{RegisterSpan{Table::input, address, count}, PollClass::custom, milliseconds{1000}, false, max_gap};
}

}  // namespace

TEST_CASE("poll plan: units that allow a gap merge across it, up to the smaller max_gap and 125 registers") {
    // Gaps of 2 and 8: bridged at max_gap 8; the read fills only the units' runs.
    auto items = fe::merge_units({bridging(0, 2, 8), bridging(4, 1, 8), bridging(13, 2, 8), bridging(24, 1, 8)});
    REQUIRE(items.size() == 2);
    CHECK(read_of(items[0]) == fp::ReadRegistersRequest{fp::fc::read_input_registers, 0, 15});
    CHECK(items[0].fills == std::vector<RegisterSpan>{{Table::input, 0, 2}, {Table::input, 4, 1}, {Table::input, 13, 2}});
    CHECK(items[0].units.size() == 3);
    CHECK(read_of(items[1]).address == 24);  // a gap of 9
    // The smaller max_gap of the two neighbours wins: 0 is today's rule.
    items = fe::merge_units({bridging(0, 2, 8), bridging(4, 1, 0)});
    CHECK(items.size() == 2);
    items = fe::merge_units({bridging(0, 2, 8), bridging(4, 1, 2), bridging(7, 1, 8)});
    REQUIRE(items.size() == 1);
    CHECK(read_of(items[0]).count == 8);
    // Never past one read.
    items = fe::merge_units({bridging(0, 100, 8), bridging(105, 20, 8), bridging(125, 1, 8)});
    REQUIRE(items.size() == 2);
    CHECK(read_of(items[0]).count == 125);
    CHECK(read_of(items[1]).address == 125);
}

TEST_CASE("poll plan: a read across gaps refused with 0x02 is split at its gaps, never bridged again") {
    PollPlan plan{fe::merge_units({bridging(0, 2, 8), bridging(2, 1, 8), bridging(6, 2, 8), bridging(10, 1, 8)})};
    REQUIRE(plan.items().size() == 1);
    const std::uint32_t id = plan.items()[0].id;
    CHECK(read_of(plan.items()[0]).count == 11);
    const auto split = plan.on_block_rejected(id);
    REQUIRE(split.size() == 3);  // the runs 0-2, 6-7, 10
    CHECK(read_of(split[0]) == fp::ReadRegistersRequest{fp::fc::read_input_registers, 0, 3});
    CHECK(read_of(split[1]) == fp::ReadRegistersRequest{fp::fc::read_input_registers, 6, 2});
    CHECK(read_of(split[2]) == fp::ReadRegistersRequest{fp::fc::read_input_registers, 10, 1});
    CHECK(plan.items().size() == 3);
    CHECK(plan.find(id) == nullptr);
    // A run refused again: halves at a unit boundary, as any block.
    const auto halves = plan.on_block_rejected(split[0].id);
    REQUIRE(halves.size() == 2);
    CHECK(read_of(halves[0]) == fp::ReadRegistersRequest{fp::fc::read_input_registers, 0, 2});
    CHECK(read_of(halves[1]) == fp::ReadRegistersRequest{fp::fc::read_input_registers, 2, 1});
    // A single unit refused alone: remembered, not polled again.
    CHECK(plan.on_block_rejected(split[2].id).empty());
    CHECK(std::vector<RegisterSpan>(plan.rejected().begin(), plan.rejected().end()) ==
          std::vector<RegisterSpan>{{Table::input, 10, 1}});
    for (const auto& item : plan.items()) {
        CHECK(item.fills.size() == 1);  // no item bridges a gap any more
    }
}
