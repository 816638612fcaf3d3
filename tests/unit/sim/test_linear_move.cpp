// LinearMove: constant-speed motion evaluated at simulated time points.
#include <doctest/doctest.h>

#include <chrono>

#include "models/linear_move.hpp"
#include "sim_test_support.hpp"

namespace fieldbridge::test {

TEST_CASE("linear move: position, end and direction") {
    const Clock::time_point t0 = SimClock{}.now();
    const sim::LinearMove up(t0, 100, 1100, 500);  // 2 s
    CHECK(up.position_at(t0) == 100);
    CHECK(up.position_at(t0 - std::chrono::seconds(1)) == 100);
    CHECK(up.position_at(t0 + std::chrono::milliseconds(1)) == 100);  // 0.5 units: rounded down
    CHECK(up.position_at(t0 + std::chrono::seconds(1)) == 600);
    CHECK(up.end() == t0 + std::chrono::seconds(2));
    CHECK_FALSE(up.done_at(t0 + std::chrono::milliseconds(1999)));
    CHECK(up.done_at(t0 + std::chrono::seconds(2)));
    CHECK(up.position_at(t0 + std::chrono::hours(5)) == 1100);

    const sim::LinearMove down(t0, 0, -300, 100);
    CHECK(down.position_at(t0 + std::chrono::milliseconds(1500)) == -150);
    CHECK(down.end() == t0 + std::chrono::seconds(3));

    const sim::LinearMove still(t0, 7, 7, 10);
    CHECK(still.done_at(t0));
    CHECK(still.position_at(t0) == 7);

    const sim::LinearMove zero_speed(t0, 0, 3, 0);  // treated as 1 unit/s
    CHECK(zero_speed.end() == t0 + std::chrono::seconds(3));
}

TEST_CASE("linear move: long moves at high rates do not overflow") {
    const Clock::time_point t0 = SimClock{}.now();
    const sim::LinearMove far(t0, -8'300'000, 8'300'000, 1);  // 192 days
    CHECK(far.position_at(t0 + std::chrono::hours(24)) == -8'300'000 + 86'400);
    CHECK(sim::distance_in(std::chrono::hours(24 * 365), 500'000) == 500'000LL * 3600 * 24 * 365);
    CHECK(sim::distance_in(std::chrono::nanoseconds(-5), 10) == 0);
}

}  // namespace fieldbridge::test
