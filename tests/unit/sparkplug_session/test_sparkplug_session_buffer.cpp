// The offline buffer: oldest first, bounded by messages and bytes, drops counted.
#include <doctest/doctest.h>

#include <string>

#include "northbound/sparkplug_session/offline_buffer.hpp"

namespace {

namespace sp = fieldbridge::northbound::sparkplug;
namespace ss = fieldbridge::northbound::sparkplug_session;

ss::BufferedData data(std::uint64_t at, std::string text = "x") {
    sp::Metric metric;
    metric.name = "position_mm";
    metric.value = std::move(text);
    return ss::BufferedData{"xeg1", {metric}, at};
}

}  // namespace

TEST_CASE("the buffer hands back everything oldest first and is empty afterwards") {
    ss::OfflineBuffer buffer(10, 1 << 20);
    for (std::uint64_t i = 1; i <= 3; ++i) buffer.push(data(i));
    CHECK(buffer.size() == 3);
    const auto all = buffer.take_all();
    REQUIRE(all.size() == 3);
    CHECK(all[0].timestamp == 1);
    CHECK(all[2].timestamp == 3);
    CHECK(buffer.size() == 0);
    CHECK(buffer.bytes() == 0);
    CHECK(buffer.dropped() == 0);
}

TEST_CASE("beyond max_messages the oldest are dropped and counted") {
    ss::OfflineBuffer buffer(2, 1 << 20);
    for (std::uint64_t i = 1; i <= 5; ++i) buffer.push(data(i));
    CHECK(buffer.dropped() == 3);
    const auto all = buffer.take_all();
    REQUIRE(all.size() == 2);
    CHECK(all[0].timestamp == 4);
    CHECK(all[1].timestamp == 5);
}

TEST_CASE("beyond max_bytes the oldest are dropped; a message larger than the bound is dropped itself") {
    const std::size_t one = ss::buffered_bytes(data(0, std::string(100, 'a')));
    ss::OfflineBuffer buffer(100, 2 * one + one / 2);
    for (std::uint64_t i = 1; i <= 4; ++i) buffer.push(data(i, std::string(100, 'a')));
    CHECK(buffer.size() == 2);
    CHECK(buffer.bytes() == 2 * one);
    CHECK(buffer.dropped() == 2);
    buffer.push(data(9, std::string(10 * one, 'b')));
    CHECK(buffer.dropped() == 3);
    CHECK(buffer.size() == 2);  // what was there stays
}

TEST_CASE("buffered_bytes counts the strings a message holds") {
    CHECK(ss::buffered_bytes(data(0, std::string(1000, 'a'))) >= ss::buffered_bytes(data(0, "a")) + 999);
}
