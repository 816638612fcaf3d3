// RegisterImage: values, times, quality, freshness, change events.
#include <doctest/doctest.h>

#include <array>
#include <chrono>
#include <vector>

#include "support.hpp"

namespace {

using namespace fbt;
using fe::ImageChange;
using fe::Quality;
using fe::RegisterImage;
using fe::Table;
using std::chrono::milliseconds;

std::vector<std::uint16_t> v(std::initializer_list<std::uint16_t> l) { return l; }

}  // namespace

TEST_CASE("image: unknown before the first read, good after") {
    RegisterImage image;
    CHECK(image.quality(Table::holding, 0x0600) == Quality::unknown);
    CHECK_FALSE(image.get(Table::holding, 0x0600).has_value());
    CHECK_FALSE(image.value(Table::holding, 0x0600).has_value());

    image.update(Table::holding, 0x0600, v({0x0A20}), t0());
    const auto e = image.get(Table::holding, 0x0600);
    REQUIRE(e.has_value());
    CHECK(e->value == 0x0A20);
    CHECK(e->quality == Quality::good);
    CHECK(e->updated == t0());
    // Tables are separate.
    CHECK_FALSE(image.value(Table::input, 0x0600).has_value());
}

TEST_CASE("image: read_fresh needs every register present, good, younger than max_age, device online") {
    RegisterImage image;
    image.update(Table::input, 0x0300, v({2000, 2}), t0());
    const auto max_age = milliseconds{200};

    CHECK(image.read_fresh(Table::input, 0x0300, 2, t0(), max_age) == v({2000, 2}));
    CHECK(image.read_fresh(Table::input, 0x0300, 2, t0() + milliseconds{199}, max_age) == v({2000, 2}));
    // Exactly max_age old is no longer fresh.
    CHECK_FALSE(image.read_fresh(Table::input, 0x0300, 2, t0() + max_age, max_age));
    // One register missing (0x0302 never read).
    CHECK_FALSE(image.read_fresh(Table::input, 0x0300, 3, t0(), max_age));
    CHECK_FALSE(image.read_fresh(Table::input, 0x02FF, 2, t0(), max_age));
    // max_age 0: never from the image.
    CHECK_FALSE(image.read_fresh(Table::input, 0x0300, 1, t0(), milliseconds{0}));
    // Count 0 is not a read.
    CHECK_FALSE(image.read_fresh(Table::input, 0x0300, 0, t0(), max_age));

    // A refresh of one register does not make an older neighbour fresh.
    image.update(Table::input, 0x0301, v({1}), t0() + milliseconds{300});
    CHECK_FALSE(image.read_fresh(Table::input, 0x0300, 2, t0() + milliseconds{300}, max_age));
    CHECK(image.read_fresh(Table::input, 0x0301, 1, t0() + milliseconds{300}, max_age) == v({1}));

    std::array<std::uint16_t, 1> out{};
    CHECK(image.read_fresh_into(Table::input, 0x0301, out, t0() + milliseconds{300}, max_age));
    CHECK(out[0] == 1);
}

TEST_CASE("image: a hole in the middle is not fresh") {
    RegisterImage image;
    image.update(Table::holding, 0x0200, v({1}), t0());
    image.update(Table::holding, 0x0202, v({2}), t0());
    CHECK_FALSE(image.read_fresh(Table::holding, 0x0200, 3, t0(), milliseconds{100}));
    // Filling the hole later inserts it in order.
    image.update(Table::holding, 0x0201, v({7}), t0());
    CHECK(image.read_fresh(Table::holding, 0x0200, 3, t0(), milliseconds{100}) == v({1, 7, 2}));
    const auto entries = image.entries(Table::holding);
    REQUIRE(entries.size() == 3);
    CHECK(entries[0].address == 0x0200);
    CHECK(entries[1].address == 0x0201);
    CHECK(entries[2].address == 0x0202);
}

TEST_CASE("image: an update that overlaps known and new registers") {
    RegisterImage image;
    image.update(Table::holding, 10, v({1, 2}), t0());
    image.update(Table::holding, 20, v({5}), t0());
    image.update(Table::holding, 11, v({9, 9, 9}), t0() + milliseconds{1});
    CHECK(values_of(image, Table::holding, 10, 4) == v({1, 9, 9, 9}));
    CHECK(image.snapshot(Table::holding).size() == 5);
    CHECK(image.get(Table::holding, 10)->updated == t0());
    CHECK(image.get(Table::holding, 12)->updated == t0() + milliseconds{1});
}

TEST_CASE("image: bits are stored as 0 / 1; the address space ends at 0xFFFF") {
    RegisterImage image;
    image.update(Table::coils, 0, v({0, 5, 1}), t0());
    CHECK(values_of(image, Table::coils, 0, 3) == v({0, 1, 1}));

    image.update(Table::holding, 0xFFFE, v({1, 2, 3}), t0());
    CHECK(image.value(Table::holding, 0xFFFF) == 2);
    CHECK(image.snapshot(Table::holding).size() == 2);
    CHECK_FALSE(image.read_fresh(Table::holding, 0xFFFF, 2, t0(), milliseconds{10}));
}

TEST_CASE("image: offline makes nothing fresh; back online everything is stale until read") {
    RegisterImage image;
    image.update(Table::input, 0x0300, v({2000, 2}), t0());
    image.set_offline(true);
    CHECK(image.offline());
    CHECK(image.quality(Table::input, 0x0300) == Quality::offline);
    CHECK(image.value(Table::input, 0x0300) == 2000);  // last known value kept
    CHECK_FALSE(image.read_fresh(Table::input, 0x0300, 2, t0(), milliseconds{100}));

    image.set_offline(false);
    CHECK(image.quality(Table::input, 0x0300) == Quality::stale);
    CHECK_FALSE(image.read_fresh(Table::input, 0x0300, 2, t0(), milliseconds{100}));
    image.update(Table::input, 0x0300, v({2000, 2}), t0() + milliseconds{5});
    CHECK(image.read_fresh(Table::input, 0x0300, 2, t0() + milliseconds{5}, milliseconds{100}));
}

TEST_CASE("image: mark_stale") {
    RegisterImage image;
    image.update(Table::holding, 1, v({1, 2, 3}), t0());
    image.mark_stale(Table::holding, 2, 5);
    CHECK(image.quality(Table::holding, 1) == Quality::good);
    CHECK(image.quality(Table::holding, 2) == Quality::stale);
    CHECK(image.quality(Table::holding, 3) == Quality::stale);
    CHECK(image.value(Table::holding, 3) == 3);
    CHECK_FALSE(image.read_fresh(Table::holding, 1, 2, t0(), milliseconds{100}));
}

TEST_CASE("image: change events list what changed, value or quality") {
    RegisterImage image;
    std::vector<ImageChange> seen;
    const auto id = image.subscribe([&seen](const ImageChange& c) { seen.push_back(c); });

    image.update(Table::holding, 5, v({1, 2}), t0());
    REQUIRE(seen.size() == 1);
    CHECK(seen[0] == ImageChange{Table::holding, {5, 6}});

    // Same values again: only the time moves, no event.
    image.update(Table::holding, 5, v({1, 2}), t0() + milliseconds{10});
    CHECK(seen.size() == 1);

    image.update(Table::holding, 5, v({1, 3}), t0() + milliseconds{20});
    REQUIRE(seen.size() == 2);
    CHECK(seen[1] == ImageChange{Table::holding, {6}});

    image.mark_stale(Table::holding, 5, 1);
    REQUIRE(seen.size() == 3);
    CHECK(seen[2] == ImageChange{Table::holding, {5}});
    // Stale -> good with the same value is a change (quality).
    image.update(Table::holding, 5, v({1}), t0() + milliseconds{30});
    REQUIRE(seen.size() == 4);
    CHECK(seen[3] == ImageChange{Table::holding, {5}});

    image.update(Table::input, 7, v({4}), t0());
    image.set_offline(true);
    // One event per table touched.
    REQUIRE(seen.size() == 7);
    CHECK(seen[5] == ImageChange{Table::holding, {5, 6}});
    CHECK(seen[6] == ImageChange{Table::input, {7}});
    image.set_offline(true);  // no change
    CHECK(seen.size() == 7);

    CHECK(image.unsubscribe(id));
    CHECK_FALSE(image.unsubscribe(id));
    image.update(Table::holding, 5, v({9}), t0());
    CHECK(seen.size() == 7);
}

TEST_CASE("image: listeners may unsubscribe and subscribe while being called") {
    RegisterImage image;
    int a_calls = 0;
    int b_calls = 0;
    int late_calls = 0;
    RegisterImage::SubscriptionId a = 0;
    a = image.subscribe([&](const ImageChange&) {
        ++a_calls;
        image.unsubscribe(a);  // itself
        (void)image.subscribe([&](const ImageChange&) { ++late_calls; });
    });
    (void)image.subscribe([&](const ImageChange&) { ++b_calls; });

    image.update(Table::holding, 1, v({1}), t0());
    CHECK(a_calls == 1);
    CHECK(b_calls == 1);
    CHECK(late_calls == 0);  // subscribed during the event: sees the next one

    image.update(Table::holding, 1, v({2}), t0());
    CHECK(a_calls == 1);
    CHECK(b_calls == 2);
    CHECK(late_calls == 1);
}

TEST_CASE("image: repeated fresh reads of 125 registers all hit") {
    RegisterImage image;
    // A few hundred registers over several tables, as a device has.
    std::vector<std::uint16_t> values(125);
    for (std::uint16_t i = 0; i < 125; ++i) values[i] = i;
    for (std::uint16_t base = 0; base < 1000; base += 125) {
        image.update(Table::holding, base, values, t0());
    }
    std::array<std::uint16_t, 125> out{};
    int hits = 0;
    for (int i = 0; i < 1000; ++i) {
        hits += image.read_fresh_into(Table::holding, 500, out, t0(), milliseconds{100}) ? 1 : 0;
    }
    CHECK(hits == 1000);
    CHECK(out[0] == 0);
    CHECK(out[124] == 124);
}
