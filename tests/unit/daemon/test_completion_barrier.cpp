#include <doctest/doctest.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "daemon/completion_barrier.hpp"

using fieldbridge::daemon::CompletionBarrier;

TEST_CASE("a barrier without tickets completes when armed") {
    int completions = 0;
    CompletionBarrier barrier([&] { ++completions; });
    CHECK_FALSE(barrier.complete());
    CHECK(completions == 0);
    barrier.arm();
    CHECK(barrier.complete());
    CHECK(completions == 1);
    barrier.arm();
    CHECK(completions == 1);
}

TEST_CASE("the barrier waits for every ticket, then completes exactly once") {
    int completions = 0;
    CompletionBarrier barrier([&] { ++completions; });
    auto tcp = barrier.expect("Modbus TCP listener");
    auto mqtt = barrier.expect("MQTT session");
    barrier.arm();
    CHECK_FALSE(barrier.complete());
    CHECK(barrier.pending() == std::vector<std::string>{"Modbus TCP listener", "MQTT session"});

    mqtt.done();
    CHECK_FALSE(barrier.complete());
    CHECK(barrier.pending() == std::vector<std::string>{"Modbus TCP listener"});
    CHECK_FALSE(mqtt.outstanding());
    CHECK(tcp.outstanding());

    mqtt.done();  // idempotent: does not count twice
    CHECK_FALSE(barrier.complete());

    tcp.done();
    CHECK(barrier.complete());
    CHECK(completions == 1);
    CHECK(barrier.pending().empty());
}

TEST_CASE("tickets finished before arm() do not complete the barrier early") {
    int completions = 0;
    CompletionBarrier barrier([&] { ++completions; });
    auto a = barrier.expect("a");
    a.done();
    CHECK(completions == 0);
    auto b = barrier.expect("b");
    barrier.arm();
    CHECK(completions == 0);
    b.done();
    CHECK(completions == 1);
}

TEST_CASE("a dropped ticket stays outstanding") {
    int completions = 0;
    CompletionBarrier barrier([&] { ++completions; });
    { auto lost = barrier.expect("serial line A"); }
    barrier.arm();
    CHECK_FALSE(barrier.complete());
    CHECK(barrier.pending() == std::vector<std::string>{"serial line A"});
}

TEST_CASE("a moved ticket carries the part; the moved-from one is empty") {
    int completions = 0;
    CompletionBarrier barrier([&] { ++completions; });
    auto first = barrier.expect("x");
    CompletionBarrier::Ticket second = std::move(first);
    barrier.arm();
    first.done();  // empty: no effect
    CHECK(completions == 0);
    CHECK(second.outstanding());
    second.done();
    CHECK(completions == 1);
}

TEST_CASE("done() after the barrier is gone is harmless") {
    auto barrier = std::make_unique<CompletionBarrier>([] {});
    auto ticket = barrier->expect("late");
    barrier.reset();
    CHECK_FALSE(ticket.outstanding());
    ticket.done();
}

TEST_CASE("the completion handler may destroy the barrier") {
    std::unique_ptr<CompletionBarrier> barrier;
    bool completed = false;
    barrier = std::make_unique<CompletionBarrier>([&] {
        completed = true;
        barrier.reset();
    });
    auto ticket = barrier->expect("only");
    barrier->arm();
    ticket.done();
    CHECK(completed);
    CHECK(barrier == nullptr);
}

TEST_CASE("expecting after completion is a programming error") {
    CompletionBarrier barrier([] {});
    barrier.arm();
    CHECK_THROWS_AS(static_cast<void>(barrier.expect("too late")), std::logic_error);
}
