#pragma once
/// @file run_until.hpp
/// Driving a test's asio loop until something happens, bounded in time: the one
/// run_until and run_for of the unit and integration tests (a broker's delivery, a
/// line's completion, a timer).
#include <chrono>

#include <asio/io_context.hpp>

namespace fieldbridge::test_support {

/// Runs @p io one handler at a time (waiting at most @p slice for one) until
/// @p done() holds or @p limit passes; false on the limit. A loop that ran out of
/// work is restarted, so a test may call it again and again.
template <typename Predicate>
bool run_until(asio::io_context& io, Predicate&& done,
               std::chrono::milliseconds limit = std::chrono::seconds{10},
               std::chrono::milliseconds slice = std::chrono::milliseconds{5}) {
    const auto deadline = std::chrono::steady_clock::now() + limit;
    while (!done()) {
        if (std::chrono::steady_clock::now() >= deadline) return false;
        if (io.stopped()) io.restart();
        io.run_one_for(slice);
    }
    return true;
}

/// Runs @p io for @p duration, whatever happens (to show that something does NOT).
inline void run_for(asio::io_context& io, std::chrono::milliseconds duration) {
    const auto deadline = std::chrono::steady_clock::now() + duration;
    while (std::chrono::steady_clock::now() < deadline) {
        if (io.stopped()) io.restart();
        io.run_one_for(std::chrono::milliseconds{2});
    }
}

}  // namespace fieldbridge::test_support
