// The tests' one launcher of fieldbridge-sim (tests/support/sim_process.hpp) against
// the real binary: started, spoken to, stopped and started again on the same link and
// control socket (what the R6 tests do to a dying controller), and every way it fails
// to start reported with what to do and the simulator's own words.
#include <doctest/doctest.h>

#include <signal.h>
#include <stdlib.h>
#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim_process.hpp"
#include "temp_dir.hpp"

namespace {

using fieldbridge::test::SimProcess;
using Args = std::vector<std::string>;

/// FIELDBRIDGE_SIM as it was, put back when the test case ends however it ends.
class SimVariable {
public:
    SimVariable() {
        if (const char* value = ::getenv("FIELDBRIDGE_SIM")) saved_ = value;
    }
    ~SimVariable() {
        if (saved_) {
            ::setenv("FIELDBRIDGE_SIM", saved_->c_str(), 1);
        } else {
            ::unsetenv("FIELDBRIDGE_SIM");
        }
    }
    SimVariable(const SimVariable&) = delete;
    SimVariable& operator=(const SimVariable&) = delete;

private:
    std::optional<std::string> saved_;
};

/// The message of the std::runtime_error @p start throws; empty when it throws none.
template <typename Start>
std::string failure_of(Start start) {
    try {
        start();
    } catch (const std::runtime_error& e) {
        return e.what();
    }
    return {};
}

}  // namespace

TEST_CASE("sim_process: started, spoken to, stopped, started again on the same link and socket") {
    SimProcess sim({"--log-level", "warn", "--bus", "{dir}/line-a:excd203mb@3"});
    CHECK(sim.running());
    CHECK(std::filesystem::exists(sim.path("line-a")));
    CHECK(sim.device_counter("line-a", 3, "frames") == 0);  // no master on the link
    CHECK(sim.bus_counter("line-a", "unanswered") == 0);
    sim.command("device line-a@3 inputs 0x0005");
    CHECK_THROWS_WITH_AS(sim.command("device line-a@3 fly"),
                         doctest::Contains("fieldbridge-sim refused the control command 'device line-a@3 fly': error:"),
                         std::runtime_error);
    CHECK_THROWS_AS(sim.start(), std::logic_error);

    CHECK(sim.terminate() == 0);
    CHECK_FALSE(sim.running());
    CHECK(sim.terminate() == 0);  // idempotent
    CHECK_FALSE(std::filesystem::exists(sim.path("line-a")));  // a clean stop removes its links
    const std::string refused = failure_of([&] { (void)sim.stats(); });
    CHECK(refused.find("cannot connect to fieldbridge-sim's control socket " + sim.path("sim.sock")) == 0);
    CHECK(refused.find("the simulator is not running") != std::string::npos);

    sim.start();
    CHECK(sim.running());
    CHECK(std::filesystem::exists(sim.path("line-a")));
    CHECK(sim.device_counter("line-a", 3, "frames") == 0);  // a new simulator, new counters
    CHECK(sim.terminate() == 0);
}

TEST_CASE("sim_process: a simulator that cannot start is reported with its command and its log") {
    const std::string exited = failure_of([] { SimProcess sim({"--bus", "{dir}/line-a:no-such-device@3"}); });
    INFO(exited);
    CHECK(exited.find("fieldbridge-sim exited with status ") == 0);
    CHECK(exited.find(" before READY; command: ") != std::string::npos);
    CHECK(exited.find("line-a:no-such-device@3 --control ") != std::string::npos);
    CHECK(exited.find("no-such-device", exited.find("its log (")) != std::string::npos);  // its own words
}

TEST_CASE("sim_process: FIELDBRIDGE_SIM unset or wrong says what to set; a binary that never says READY is killed") {
    const SimVariable restored;
    ::unsetenv("FIELDBRIDGE_SIM");
    CHECK(failure_of([] { SimProcess sim(Args{}); })
              .find("FIELDBRIDGE_SIM is not set: it must name the fieldbridge-sim binary") == 0);
    ::setenv("FIELDBRIDGE_SIM", "/nonexistent/fieldbridge-sim", 1);
    CHECK(failure_of([] { SimProcess sim(Args{}); })
              .find("FIELDBRIDGE_SIM=/nonexistent/fieldbridge-sim is not an executable fieldbridge-sim") == 0);

    // A binary that never says READY: refused after the bound, and not left running.
    const fieldbridge::test::TempDir tmp("fb-sim-silent");
    const auto silent = tmp.path() / "silent-sim";
    const auto pid_file = tmp.path() / "pid";
    std::ofstream(silent) << "#!/bin/sh\necho $$ > " << pid_file.string() << "\nexec sleep 30\n";
    std::filesystem::permissions(silent, std::filesystem::perms::owner_all);
    ::setenv("FIELDBRIDGE_SIM", silent.c_str(), 1);
    const std::string slow = failure_of([] { SimProcess sim(Args{}, std::chrono::milliseconds{300}); });
    CHECK(slow.find("fieldbridge-sim did not print READY within 300 ms") == 0);
    pid_t pid = 0;
    std::ifstream(pid_file) >> pid;
    REQUIRE(pid > 0);
    CHECK(::kill(pid, 0) == -1);  // killed and reaped
}
