// Issue 3, "echo, garbage and CRC errors are discarded and counted": a 2-wire adapter
// with local echo, random bytes ahead of replies, replies with a damaged CRC. Requests
// still succeed (a read after a retry when its reply was damaged) and the line
// master's counters show what was thrown away.
#include <doctest/doctest.h>
#include <fmt/format.h>

#include <array>

#include "engine_harness.hpp"
#include "sim_process.hpp"

namespace fieldbridge::integration {
namespace {

using engine::OutcomeStatus;
using engine::Priority;
using engine::Table;
using test::SimProcess;

constexpr std::array<const char*, 3> polled{"xeg", "excd", "ascii"};

/// One read of something each polled device has, through the line (max_age 0).
void every_device_answers(EngineHarness& h) {
    const auto xeg = h.request(h.device("xeg"), read_input(0x0300, 2));
    CHECK_MESSAGE((xeg && registers_of(*xeg).size() == 2), "xeg: ", describe(xeg));
    const auto excd = h.request(h.device("excd"), read_holding(0x0200, 11));
    CHECK_MESSAGE((excd && registers_of(*excd).size() == 11), "excd: ", describe(excd));
    const auto ascii = h.request(h.device("ascii"), read_holding(0x0202));
    CHECK_MESSAGE((ascii && registers_of(*ascii).size() == 1), "ascii: ", describe(ascii));
}

std::uint64_t polls_ok(const EngineHarness& h, std::string_view name) {
    return h.stats(name).of(Priority::poll).outcome(OutcomeStatus::ok);
}

TEST_CASE("engine.noise: echo garbage and CRC errors are discarded and counted") {
    // The adapter echoes every request from the start, as a real one would.
    SimProcess sim({"--bus", "{dir}/line-a:hiwin-xeg@2,excd203mb@3,excd203mb@4,wtec-ascii@5", "--wire-time", "--baud",
                    "115200", "--fault", "line-a:echo"});
    EngineHarness h(fmt::format(R"(
gateway: {{ id: engine-it }}
lines:
  - name: line-a
    port: {}
    local_echo: true
    read_retries: 1
    devices:
      - {{ name: xeg, type: hiwin-xeg, address: 2, unit_id: 1, max_age: 0ms }}
      - {{ name: excd, type: excd203mb, address: 3, unit_id: 2, max_age: 0ms }}
      - {{ name: quiet, type: excd203mb, address: 4, unit_id: 3, max_age: 0ms, poll: {{ fast: 60min, slow: 60min }} }}
      - {{ name: ascii, type: wtec-ascii, address: 5, unit_id: 4, stroke: 20000, max_age: 0ms }}
)",
                                sim.path("line-a")));
    h.start();
    const auto& counters = h.line("line-a").master().counters();
    REQUIRE(h.run_until(
        [&] {
            for (const char* name : polled) {
                if (!h.device(name).online() || polls_ok(h, name) < 3) return false;
            }
            return good_value(h.device("quiet"), Table::holding, 0x0001).has_value();
        },
        seconds{3}));

    SUBCASE("local echo") {
        const auto before = counters;
        const auto echoes_before = sim.bus_counter("line-a", "echoes");
        h.run_for(seconds{1});
        every_device_answers(h);
        CHECK(counters.requests > before.requests + 20);
        CHECK(counters.echo_mismatch == 0);
        CHECK(counters.crc_errors == before.crc_errors);
        // Every byte sent came back once as echo, before the replies.
        CHECK(counters.bytes_rx - before.bytes_rx > counters.bytes_tx - before.bytes_tx);
        CHECK(sim.bus_counter("line-a", "echoes") - echoes_before >= counters.requests - before.requests);
    }

    SUBCASE("garbage ahead of replies") {
        const auto before = counters;
        std::array<std::uint64_t, polled.size()> polls_before{};
        for (std::size_t i = 0; i < polled.size(); ++i) polls_before[i] = polls_ok(h, polled[i]);
        sim.command("fault line-a:garbage");
        CHECK(h.run_until(
            [&] {
                for (std::size_t i = 0; i < polled.size(); ++i) {
                    if (polls_ok(h, polled[i]) < polls_before[i] + 10) return false;
                }
                return true;
            },
            seconds{3}));
        every_device_answers(h);
        sim.command("fault line-a:garbage:off");
        CHECK(counters.garbage_bytes > before.garbage_bytes);
        CHECK(sim.device_counter("line-a", 2, "garbage_injected") > 0);
        CHECK(sim.device_counter("line-a", 5, "garbage_injected") > 0);
        for (const char* name : polled) CHECK(h.device(name).online());
        MESSAGE("garbage: ", counters.garbage_bytes - before.garbage_bytes, " bytes dropped, ",
                counters.timeouts - before.timeouts, " timeouts, ", counters.crc_errors - before.crc_errors,
                " CRC errors over ", counters.requests - before.requests, " requests");
    }

    SUBCASE("a damaged CRC is dropped and the read retried") {
        auto& quiet = h.device("quiet");
        const auto crc_before = counters.crc_errors;
        const auto frames_before = sim.device_counter("line-a", 4, "frames");
        sim.command("fault line-a@4:corrupt-crc:next=1");
        const auto answer = h.request(quiet, read_holding(0x0001));
        CHECK_MESSAGE((answer && registers_of(*answer).size() == 1), describe(answer));
        CHECK(counters.crc_errors == crc_before + 1);
        CHECK(h.stats("quiet").of(Priority::on_demand).retries == 1);
        CHECK(sim.device_counter("line-a", 4, "frames") == frames_before + 2);
        CHECK(sim.device_counter("line-a", 4, "corrupted") == 1);

        // The same for WTEC ASCII frames (their CRC is four hex digits): polls retried.
        const auto ascii_retries = h.stats("ascii").of(Priority::poll).retries;
        sim.command("fault line-a@5:corrupt-crc:next=2");
        CHECK(h.run_until([&] { return counters.crc_errors >= crc_before + 3; }, seconds{2}));
        CHECK(h.stats("ascii").of(Priority::poll).retries >= ascii_retries + 1);
        CHECK(h.device("ascii").online());
        every_device_answers(h);
    }
    h.stop();
    CHECK(sim.terminate() == 0);
}

}  // namespace
}  // namespace fieldbridge::integration
