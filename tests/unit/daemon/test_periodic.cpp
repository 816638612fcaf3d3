#include <doctest/doctest.h>

#include <chrono>
#include <stdexcept>
#include <vector>

#include <asio/io_context.hpp>
#include <asio/post.hpp>

#include "core/error.hpp"
#include "daemon/periodic.hpp"

using fieldbridge::daemon::Periodic;
using namespace std::chrono_literals;

TEST_CASE("ticks every period until cancelled") {
    asio::io_context io;
    int ticks = 0;
    std::chrono::steady_clock::time_point last;
    Periodic periodic(io, 5ms, [&] {
        last = std::chrono::steady_clock::now();
        ++ticks;
    });
    Periodic stopper(io, 1ms, [&] {
        if (ticks == 4) {
            periodic.cancel();
        }
    });
    const auto started = std::chrono::steady_clock::now();
    periodic.start(false);
    stopper.start(false);
    io.run_for(2s);  // returns early once nothing is pending
    CHECK(ticks == 4);
    CHECK_FALSE(periodic.running());
    CHECK(last - started >= 20ms);  // the 4th tick is not due before four periods
}

TEST_CASE("start(true) ticks at once; cancel() before the deadline prevents the tick") {
    asio::io_context io;
    int ticks = 0;
    Periodic periodic(io, 1h, [&] { ++ticks; });
    periodic.start(true);
    CHECK(ticks == 1);
    CHECK(periodic.running());
    asio::post(io, [&] { periodic.cancel(); });
    io.run_for(2s);
    CHECK(ticks == 1);
    CHECK(io.stopped());  // the cancelled wait left nothing behind
}

TEST_CASE("a tick already queued when cancel() runs is dropped") {
    asio::io_context io;
    int ticks = 0;
    Periodic periodic(io, 1ms, [&] { ++ticks; });
    periodic.start(false);
    // Let the deadline pass without running the loop, so the completion is ready
    // when the loop starts; the cancel below runs before it.
    const auto until = std::chrono::steady_clock::now() + 5ms;
    while (std::chrono::steady_clock::now() < until) {
    }
    asio::post(io, [&] { periodic.cancel(); });
    io.run_for(2s);
    CHECK(ticks == 0);
}

TEST_CASE("a stalled loop does not produce a burst of ticks") {
    asio::io_context io;
    std::vector<std::chrono::steady_clock::time_point> ticks;
    std::chrono::steady_clock::time_point stall_end;
    Periodic periodic(io, 5ms, [&] {
        ticks.push_back(std::chrono::steady_clock::now());
        if (ticks.size() == 1) {
            // Block the loop for five periods, as a hung handler would.
            const auto until = std::chrono::steady_clock::now() + 25ms;
            while (std::chrono::steady_clock::now() < until) {
            }
            stall_end = std::chrono::steady_clock::now();
        }
    });
    periodic.start(false);
    Periodic stopper(io, 1ms, [&] {
        if (ticks.size() >= 4) {
            periodic.cancel();
            stopper.cancel();
        }
    });
    stopper.start(false);
    io.run_for(2s);
    // The five missed deadlines are skipped: right after the stall at most the
    // next deadline (and, by alignment, the one after) fire, not five in a row.
    std::size_t right_after = 0;
    for (const auto& tick : ticks) {
        right_after += (tick >= stall_end && tick <= stall_end + 1ms) ? 1U : 0U;
    }
    CHECK(ticks.size() >= 4);
    CHECK(right_after <= 2);
}

TEST_CASE("a non-positive period is refused") {
    asio::io_context io;
    CHECK_THROWS_AS(Periodic(io, 0ms, [] {}), fieldbridge::core::InvalidArgument);
}
