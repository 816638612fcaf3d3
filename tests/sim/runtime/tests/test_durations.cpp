#include <doctest/doctest.h>

#include "durations.hpp"
#include "sim_error.hpp"

namespace fieldbridge::sim::runtime {

using namespace std::chrono_literals;

TEST_CASE("durations with and without units") {
    CHECK(parse_duration("1ms", DefaultUnit::seconds, "t") == 1ms);
    CHECK(parse_duration("250us", DefaultUnit::seconds, "t") == 250us);
    CHECK(parse_duration("1.5s", DefaultUnit::milliseconds, "t") == 1500ms);
    CHECK(parse_duration("2m", DefaultUnit::milliseconds, "t") == 120s);
    CHECK(parse_duration("60", DefaultUnit::seconds, "t") == 60s);
    CHECK(parse_duration("3", DefaultUnit::milliseconds, "t") == 3ms);
    CHECK(parse_duration("0", DefaultUnit::milliseconds, "t") == 0ms);
}

TEST_CASE("bad durations name the option") {
    CHECK_THROWS_AS((void)parse_duration("", DefaultUnit::seconds, "--duration"), SimError);
    CHECK_THROWS_AS((void)parse_duration("ms", DefaultUnit::seconds, "--duration"), SimError);
    CHECK_THROWS_AS((void)parse_duration("-1s", DefaultUnit::seconds, "--duration"), SimError);
    CHECK_THROWS_AS((void)parse_duration("5 parsecs", DefaultUnit::seconds, "--duration"), SimError);
    CHECK_THROWS_AS((void)parse_duration("9999999h", DefaultUnit::seconds, "--duration"), SimError);
    try {
        (void)parse_duration("5x", DefaultUnit::seconds, "--turnaround");
        FAIL("no exception");
    } catch (const SimError& e) {
        CHECK(std::string(e.what()).find("--turnaround") != std::string::npos);
    }
}

}  // namespace fieldbridge::sim::runtime
