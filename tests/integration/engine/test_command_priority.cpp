// Issue 3, "a command overtakes queued polls" (spec §3 rule 2): many on-demand reads
// queued for one device, then a write; the write waits for the transaction in flight
// and nothing else, so at most one of the reads queued before it completes first.
#include <doctest/doctest.h>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>

#include "engine_harness.hpp"
#include "sim_process.hpp"

namespace fieldbridge::integration {
namespace {

using engine::Priority;
using engine::Table;
using test::SimProcess;

TEST_CASE("engine.priority: a write overtakes the on-demand reads queued before it") {
    SimProcess sim({"--bus", "{dir}/line-a:hiwin-xeg@2,excd203mb@3", "--wire-time", "--baud", "115200"});
    // max_age 0: every read goes to the line; a queue long enough for the burst.
    EngineHarness h(fmt::format(R"(
gateway: {{ id: engine-it }}
lines:
  - name: line-a
    port: {}
    devices:
      - {{ name: xeg, type: hiwin-xeg, address: 2, unit_id: 1 }}
      - {{ name: excd, type: excd203mb, address: 3, unit_id: 2, max_age: 0ms, queue_limit: 64, command_ttl: 2s }}
)",
                                sim.path("line-a")));
    h.start();
    auto& excd = h.device("excd");
    REQUIRE(h.run_until([&] { return excd.online() && good_value(excd, Table::holding, 0x0001).has_value(); },
                        seconds{3}));
    const std::uint16_t before = *good_value(excd, Table::holding, 0x0001);
    const std::uint16_t written = before == 200 ? 201 : 200;  // hvs, 1-0x1388

    constexpr int reads = 12;
    constexpr int write_tag = -1;
    std::vector<int> order;  // completion order: read index, or write_tag
    int bad = 0;
    for (int i = 0; i < reads; ++i) {
        excd.request(read_holding(0x0200, 11), [&order, &bad, i](const protocol::Response& response) {
            if (registers_of(response).size() != 11) ++bad;
            order.push_back(i);
        });
    }
    std::optional<protocol::Response> write_answer;
    excd.request(write_register(0x0001, written), [&](const protocol::Response& response) {
        write_answer = response;
        order.push_back(write_tag);
    });
    REQUIRE(h.run_until([&] { return order.size() == reads + 1; }, seconds{5}));

    CHECK(bad == 0);
    REQUIRE(write_answer.has_value());
    CHECK_MESSAGE(std::holds_alternative<protocol::WriteSingleResponse>(*write_answer), describe(write_answer));
    const auto write_position = std::find(order.begin(), order.end(), write_tag) - order.begin();
    INFO("completion order (", write_tag, " is the write): ", fmt::format("{}", fmt::join(order, " ")));
    MESSAGE("the write completed after ", write_position, " of the ", reads, " reads queued before it");
    CHECK(write_position <= 1);
    // The reads that were overtaken keep their own order (first come, first served).
    std::vector<int> read_order;
    for (int tag : order) {
        if (tag != write_tag) read_order.push_back(tag);
    }
    CHECK(std::is_sorted(read_order.begin(), read_order.end()));

    const auto& stats = h.stats("excd");
    CHECK(stats.of(Priority::command).outcome(engine::OutcomeStatus::ok) == 1);
    CHECK(stats.of(Priority::on_demand).outcome(engine::OutcomeStatus::ok) >= reads);
    CHECK(h.read_register(excd, 0x0001) == written);
    h.stop();
    CHECK(sim.terminate() == 0);
}

}  // namespace
}  // namespace fieldbridge::integration
