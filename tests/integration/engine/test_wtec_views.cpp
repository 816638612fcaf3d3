// Issue 3, "WTEC ASCII reads and writes through the uniform view match what the same
// gripper shows in RTU mode": one WTEC-485 in ASCII mode on one line, one in RTU mode
// on another, both with the simulator's default stroke (20000 counts, the ASCII
// device's configured `stroke`). The same register writes go to both through
// DeviceAgent::request, and the registers of the RTU map (docs/registers.md) read the
// same through both after each step.
#include <doctest/doctest.h>
#include <fmt/format.h>

#include <array>

#include "engine_harness.hpp"
#include "sim_process.hpp"

namespace fieldbridge::integration {
namespace {

using engine::Table;
using test::SimProcess;

/// The readable registers of the uniform map, except 0x0302 (W only in the ASCII
/// view) and 0x0303 (each device's own address). Force 0x0103 is the `N` max (grip)
/// current over the `R` max current in both (docs/registers.md).
constexpr std::array<std::uint16_t, 8> compared{0x0102, 0x0103, 0x0104, 0x0105, 0x0200, 0x0202, 0x0204, 0x0300};

class TwoFaces {
public:
    TwoFaces(EngineHarness& h, SimProcess& sim)
        : h_(h), sim_(sim), ascii_(h.device("ascii")), rtu_(h.device("rtu")) {}

    /// The same write to both; both must acknowledge it.
    void write(std::uint16_t address, std::uint16_t value) {
        for (auto* agent : {&ascii_, &rtu_}) {
            const auto answer = h_.request(*agent, write_register(address, value));
            INFO(agent->config().name, ": write 0x", fmt::format("{:04X}", address), " = ", value);
            REQUIRE_MESSAGE(answer.has_value(), describe(answer));
            CHECK_MESSAGE(std::holds_alternative<protocol::WriteSingleResponse>(*answer), describe(answer));
        }
    }
    /// The same control command for both simulated grippers.
    void both(std::string_view command) {
        sim_.command(fmt::format("device line-a@5 {}", command));
        sim_.command(fmt::format("device line-b@1 {}", command));
    }
    /// Reads @p address from both (through the line: max_age 0).
    std::pair<std::optional<std::uint16_t>, std::optional<std::uint16_t>> read(std::uint16_t address) {
        return {h_.read_register(ascii_, address), h_.read_register(rtu_, address)};
    }
    /// Until both read @p value at @p address.
    bool wait_for(std::uint16_t address, std::uint16_t value, engine::Duration timeout = seconds{5}) {
        return h_.run_until(
            [&] {
                const auto [a, r] = read(address);
                return a == value && r == value;
            },
            timeout, milliseconds{20});
    }
    /// Every compared register reads the same, known value through both.
    void same_state(std::string_view step) {
        for (const std::uint16_t address : compared) {
            const auto [a, r] = read(address);
            INFO(step, ": register 0x", fmt::format("{:04X}", address), " ascii ", a.value_or(0xFFFF), " rtu ",
                 r.value_or(0xFFFF));
            CHECK(a.has_value());
            CHECK(r.has_value());
            CHECK(a == r);
        }
    }

private:
    EngineHarness& h_;
    SimProcess& sim_;
    engine::DeviceAgent& ascii_;
    engine::DeviceAgent& rtu_;
};

TEST_CASE("engine.wtec_views: the WTEC ASCII view shows what the same gripper shows in RTU mode") {
    SimProcess sim({"--bus", "{dir}/line-a:wtec-ascii@5", "--bus", "{dir}/line-b:wtec-rtu@1", "--wire-time", "--baud",
                    "115200"});
    EngineHarness h(fmt::format(R"(
gateway: {{ id: engine-it }}
lines:
  - name: line-a
    port: {}
    devices:
      - {{ name: ascii, type: wtec-ascii, address: 5, unit_id: 1, stroke: 20000, max_age: 0ms, command_ttl: 1s,
           poll: {{ slow: 200ms }} }}
  - name: line-b
    port: {}
    devices:
      - {{ name: rtu, type: wtec-rtu, address: 1, unit_id: 2, max_age: 0ms, command_ttl: 1s }}
)",
                                sim.path("line-a"), sim.path("line-b")));
    h.start();
    auto& ascii = h.device("ascii");
    // The ASCII view translates force and speed writes with the `R` and `N` values.
    REQUIRE(h.run_until(
        [&] {
            return ascii.online() && h.device("rtu").online() && good_value(ascii, Table::holding, 0x0103) &&
                   good_value(ascii, Table::holding, 0x0104) && good_value(ascii, Table::holding, 0x0300);
        },
        seconds{3}));
    TwoFaces grippers(h, sim);
    grippers.same_state("power-up");
    CHECK(grippers.read(0x0103).second == 100);  // N max 0x3F over R max 0x3F
    CHECK(grippers.read(0x0200).second == 0);  // not initialised
    CHECK(grippers.read(0x0202).second == 11);  // motor released

    // Initialise (home at the open end) and wait for "initialised" on both.
    grippers.write(0x0100, 1);
    REQUIRE(grippers.wait_for(0x0200, 1));
    REQUIRE(grippers.wait_for(0x0202, 1));
    grippers.same_state("initialised");

    // Force (the grip current round(60 x 63 / 100) = 38 in both: 60 %), speed, then a
    // move to half the stroke.
    grippers.write(0x0103, 60);
    grippers.write(0x0104, 50);
    grippers.write(0x0105, 50);
    REQUIRE(grippers.wait_for(0x0204, 50));
    REQUIRE(grippers.wait_for(0x0202, 1));
    grippers.same_state("moved to 50 %");
    CHECK(grippers.read(0x0103).second == 60);
    CHECK(grippers.read(0x0104).second == 50);
    // 80 % is round(50.4) = 50, which both read as 79 %.
    grippers.write(0x0103, 80);
    REQUIRE(grippers.wait_for(0x0103, 79));

    // An object that leaves 30 % of the opening: closing fully grips it.
    grippers.both("object 30");
    grippers.write(0x0105, 100);
    REQUIRE(grippers.wait_for(0x0202, 2));
    grippers.same_state("gripped");

    // Opening again releases it and reaches the target.
    grippers.both("object none");
    grippers.write(0x0105, 20);
    REQUIRE(grippers.wait_for(0x0204, 20));
    REQUIRE(grippers.wait_for(0x0202, 1));
    grippers.same_state("moved to 20 %");

    // E-stop latches until the next initialisation.
    grippers.write(0x0102, 1);
    REQUIRE(grippers.wait_for(0x0102, 1));
    REQUIRE(grippers.wait_for(0x0202, 11));
    grippers.same_state("e-stopped");
    grippers.write(0x0100, 1);
    REQUIRE(grippers.wait_for(0x0102, 0));
    REQUIRE(grippers.wait_for(0x0200, 1));
    REQUIRE(grippers.wait_for(0x0202, 1));
    grippers.same_state("initialised again");

    // Init direction: a parameter write both views read back.
    grippers.write(0x0300, 2);
    REQUIRE(grippers.wait_for(0x0300, 2));
    grippers.same_state("init direction close");
    h.stop();
    CHECK(sim.terminate() == 0);
}

}  // namespace
}  // namespace fieldbridge::integration
