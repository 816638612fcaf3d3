// Issue 3, "polling fills the image": the demo cell's four devices on two simulated
// lines; after a short run every device is online and the registers of its poll plan
// are good, with the values the simulator was given through its control socket.
#include <doctest/doctest.h>
#include <fmt/format.h>

#include "engine_harness.hpp"
#include "sim_process.hpp"

namespace fieldbridge::integration {
namespace {

using engine::Table;
using test::SimProcess;

std::string cell_yaml(const SimProcess& sim) {
    return fmt::format(R"(
gateway: {{ id: engine-it }}
lines:
  - name: line-a
    port: {}
    devices:
      - {{ name: xeg, type: hiwin-xeg, address: 2, unit_id: 1, poll: {{ slow: 200ms }} }}
      - {{ name: excd, type: excd203mb, address: 3, unit_id: 2, poll: {{ slow: 200ms }} }}
      - {{ name: ascii, type: wtec-ascii, address: 5, unit_id: 3, stroke: 20000, poll: {{ slow: 200ms }} }}
  - name: line-b
    port: {}
    devices:
      - {{ name: rtu, type: wtec-rtu, address: 1, unit_id: 4, poll: {{ slow: 200ms }} }}
)",
                       sim.path("line-a"), sim.path("line-b"));
}

/// Every register of [first, first + count) of @p table is good.
bool all_good(const engine::DeviceAgent& agent, Table table, std::uint16_t first, std::uint16_t count) {
    for (std::uint32_t a = first; a < std::uint32_t{first} + count; ++a) {
        if (!good_value(agent, table, static_cast<std::uint16_t>(a))) return false;
    }
    return true;
}

TEST_CASE("engine.poll: polling fills the image of every device on two lines") {
    SimProcess sim({"--bus", "{dir}/line-a:hiwin-xeg@2/model=0x0A40,excd203mb@3,wtec-ascii@5", "--bus",
                    "{dir}/line-b:wtec-rtu@1", "--wire-time", "--baud", "115200"});
    // Values the engine can only know by reading them from the devices.
    sim.command("device line-a@2 inputs 0x22");     // XEG IN2 and IN6 (seed 001 FC02 example)
    sim.command("device line-a@3 inputs 0x0005");   // EXCD rin
    sim.command("device line-a@5 position 5000");   // WTEC ASCII: 25 % of 20000
    sim.command("device line-b@1 position 10000");  // WTEC RTU: 50 % of 20000

    EngineHarness h(cell_yaml(sim));
    h.start();
    auto& xeg = h.device("xeg");
    auto& excd = h.device("excd");
    auto& ascii = h.device("ascii");
    auto& rtu = h.device("rtu");

    // Every item of every plan: fast and slow (200 ms) and the startup reads.
    const auto plans_read = [&] {
        return xeg.online() && excd.online() && ascii.online() && rtu.online() &&
               all_good(xeg, Table::input, 0x0300, 2) && all_good(xeg, Table::input, 0x0303, 4) &&
               all_good(xeg, Table::holding, 0x0600, 1) && all_good(xeg, Table::discrete_inputs, 0x0000, 8) &&
               all_good(xeg, Table::discrete_inputs, 0x0010, 8) && all_good(excd, Table::holding, 0x0200, 11) &&
               all_good(excd, Table::holding, 0x02D4, 3) && all_good(excd, Table::holding, 0x0000, 0x32) &&
               all_good(ascii, Table::holding, 0x0200, 1) && all_good(ascii, Table::holding, 0x0202, 1) &&
               all_good(ascii, Table::holding, 0x0204, 1) && all_good(ascii, Table::holding, 0x0103, 3) &&
               all_good(ascii, Table::holding, 0x0300, 1) && all_good(ascii, Table::input, 0x1000, 0x32) &&
               all_good(rtu, Table::holding, 0x0200, 1) && all_good(rtu, Table::holding, 0x0202, 1) &&
               all_good(rtu, Table::holding, 0x0204, 1) && all_good(rtu, Table::holding, 0x0102, 4) &&
               all_good(rtu, Table::holding, 0x0300, 1) && all_good(rtu, Table::holding, 0x0302, 2);
    };
    REQUIRE_MESSAGE(h.run_until(plans_read, seconds{5}), h.engine().status());
    CHECK(h.engine().status() == "lines 2/2 up, devices 4/4 online");

    // XEG (docs/registers.md, hiwin-xeg): powered up closed, idle; the model and the
    // firmware of the simulator; DI IN2 and IN6 as wired above.
    CHECK(good_value(xeg, Table::input, 0x0300) == 0);
    CHECK(good_value(xeg, Table::input, 0x0301) == 0);
    CHECK(good_value(xeg, Table::holding, 0x0600) == 0x0A40);
    CHECK(good_value(xeg, Table::input, 0x0303) == 3);
    CHECK(good_value(xeg, Table::input, 0x0306) == 884);
    for (std::uint16_t bit = 0; bit < 8; ++bit) {
        CHECK(good_value(xeg, Table::discrete_inputs, bit) == ((0x22 >> bit) & 1));
    }
    // EXCD203MB: rin as set, idle (rby 1), ver 120 high word first.
    CHECK(good_value(excd, Table::holding, 0x0203) == 0x0005);
    CHECK(good_value(excd, Table::holding, 0x0205) == 1);
    CHECK(good_value(excd, Table::holding, 0x0207) == 0);
    CHECK(good_value(excd, Table::holding, 0x0208) == 120);
    // WTEC ASCII view: not homed (0x0200 0), motor released (grip 11), position from
    // the `I` counts, its own address at 0x0303, init direction open (B mode 0xFC).
    CHECK(good_value(ascii, Table::holding, 0x0200) == 0);
    CHECK(good_value(ascii, Table::holding, 0x0202) == 11);
    CHECK(good_value(ascii, Table::holding, 0x0204) == 25);
    CHECK(good_value(ascii, Table::input, 0x1001) == 5000);
    CHECK(good_value(ascii, Table::holding, 0x0303) == 5);
    CHECK(good_value(ascii, Table::holding, 0x0300) == 1);
    // WTEC RTU: the same power-up state through the RTU map.
    CHECK(good_value(rtu, Table::holding, 0x0200) == 0);
    CHECK(good_value(rtu, Table::holding, 0x0202) == 11);
    CHECK(good_value(rtu, Table::holding, 0x0204) == 50);
    CHECK(good_value(rtu, Table::holding, 0x0303) == 1);
    CHECK(good_value(rtu, Table::holding, 0x0300) == 1);

    // A change on the device reaches the image by polling alone (fast: rin; slow: DI).
    sim.command("device line-a@3 inputs 0x0009");
    sim.command("device line-a@2 inputs 0x01");
    CHECK(h.run_until(
        [&] {
            return good_value(excd, Table::holding, 0x0203) == 0x0009 &&
                   good_value(xeg, Table::discrete_inputs, 0x0000) == 1 &&
                   good_value(xeg, Table::discrete_inputs, 0x0001) == 0;
        },
        seconds{2}));

    // Nothing was damaged and the engine kept the silence before every request. (Not
    // timeouts: on a loaded machine the simulator itself may answer late.)
    for (const auto& line : h.engine().lines()) {
        const auto& counters = line.worker->master().counters();
        INFO("line ", line.worker->config().name);
        CHECK(counters.replies > 0);
        CHECK(counters.crc_errors == 0);
        CHECK(counters.bad_replies == 0);
    }
    CHECK(sim.bus_counter("line-a", "gap_violations") == 0);
    CHECK(sim.bus_counter("line-b", "gap_violations") == 0);
    h.stop();
    CHECK(sim.terminate() == 0);
}

}  // namespace
}  // namespace fieldbridge::integration
