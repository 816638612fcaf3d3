#include <doctest/doctest.h>

#include <chrono>

#include "daemon/watchdog.hpp"

using namespace std::chrono_literals;
using fieldbridge::daemon::min_watchdog_ping_interval;
using fieldbridge::daemon::watchdog_ping_interval;

TEST_CASE("the watchdog is pinged at half the timeout") {
    // WatchdogSec=10 in deploy/fieldbridge.service: systemd sets WATCHDOG_USEC=10000000.
    CHECK(watchdog_ping_interval(std::chrono::microseconds{10'000'000}) == std::chrono::microseconds{5'000'000});
    CHECK(watchdog_ping_interval(std::chrono::microseconds{200'000}) == std::chrono::microseconds{100'000});
    CHECK(watchdog_ping_interval(std::chrono::microseconds{3'001}) == std::chrono::microseconds{1'500});
}

TEST_CASE("no watchdog, no pings") {
    CHECK_FALSE(watchdog_ping_interval(std::nullopt).has_value());
    CHECK_FALSE(watchdog_ping_interval(std::chrono::microseconds{0}).has_value());
    CHECK_FALSE(watchdog_ping_interval(std::chrono::microseconds{-5}).has_value());
}

TEST_CASE("an absurdly short timeout does not turn into a busy loop") {
    CHECK(watchdog_ping_interval(std::chrono::microseconds{1}) == min_watchdog_ping_interval);
    CHECK(watchdog_ping_interval(std::chrono::microseconds{1'999}) == min_watchdog_ping_interval);
    CHECK(watchdog_ping_interval(std::chrono::microseconds{2'000}) == 1ms);
    CHECK(watchdog_ping_interval(std::chrono::microseconds{2'002}) == std::chrono::microseconds{1'001});
}
