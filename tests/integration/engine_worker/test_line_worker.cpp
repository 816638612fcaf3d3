// The line worker over a real pseudo-terminal: request/reply round trips, priority,
// deadlines, retries, local echo and garbage, with a scripted device on the pty's
// master side.
#include "pty_device.hpp"

namespace {

using namespace worker_test;

TEST_CASE("worker: a poll goes out and completes ok with the device's reply") {
    Bench bench;
    bench.start();
    bench.worker->submit(tagged(read_tx(1, Priority::poll, 0x0100, 3), bench.recorder, "poll"));
    REQUIRE(run_until(bench.io, [&] { return bench.recorder.total() == 1; }));

    const auto& outcome = bench.recorder.outcome("poll");
    CHECK(outcome.status == OutcomeStatus::ok);
    CHECK(outcome.attempts == 1);
    CHECK(values_of(outcome) == std::vector<std::uint16_t>{PtyDevice::value_at(0x100), PtyDevice::value_at(0x101),
                                                           PtyDevice::value_at(0x102)});
    REQUIRE(bench.device.requests().size() == 1);
    CHECK(bench.device.requests()[0].address == 1);
    CHECK(bench.device.unframed_bytes() == 0);
    CHECK(bench.worker->master().counters().replies == 1);
    CHECK(bench.states == std::vector<bool>{true});
    CHECK(bench.logs.contains(fe::LogLevel::info, "open"));
}

TEST_CASE("worker: polls submitted from their completions keep the line busy, one at a time") {
    Bench bench;
    bench.start();
    int remaining = 50;
    std::function<void(const fe::Outcome&)> again;
    std::size_t ok = 0;
    again = [&](const fe::Outcome& outcome) {
        ok += outcome.status == OutcomeStatus::ok ? 1 : 0;
        if (--remaining > 0) {
            Transaction t = read_tx(static_cast<std::uint8_t>(1 + remaining % 2), Priority::poll);
            t.on_done = again;
            bench.worker->submit(std::move(t));
        }
    };
    Transaction first = read_tx(1, Priority::poll);
    first.on_done = again;
    bench.worker->submit(std::move(first));
    REQUIRE(run_until(bench.io, [&] { return remaining == 0; }));
    CHECK(ok == 50);
    CHECK(bench.device.requests().size() == 50);
    CHECK(bench.worker->master().counters().garbage_bytes == 0);
}

TEST_CASE("worker: a command submitted while polls are queued goes next") {
    Bench bench;
    bench.start();
    // The command is submitted from the first poll's completion, when three more
    // polls wait in the queue.
    Transaction first = read_tx(1, Priority::poll);
    first.on_done = [&](const fe::Outcome&) {
        bench.worker->submit(tagged(write_tx(2, 0x0010, 7), bench.recorder, "command"));
    };
    bench.worker->submit(std::move(first));
    for (int i = 0; i < 3; ++i) {
        bench.worker->submit(tagged(read_tx(static_cast<std::uint8_t>(1 + i % 2), Priority::poll),
                                    bench.recorder, "poll" + std::to_string(i)));
    }
    REQUIRE(run_until(bench.io, [&] { return bench.recorder.total() == 4; }));
    CHECK(bench.recorder.status("command") == OutcomeStatus::ok);
    const auto functions = bench.device.functions();
    REQUIRE(functions.size() == 5);
    CHECK(functions[0] == fp::fc::read_holding_registers);
    CHECK(functions[1] == fp::fc::write_single_register);
    CHECK(bench.recorder.order().front() == "command");
}

TEST_CASE("worker: a command whose deadline passes behind the transaction in flight never reaches the wire") {
    Bench bench;
    bench.start();
    bench.device.script.silent.insert(fp::fc::read_holding_registers);  // the poll times out (30 ms)
    Transaction poll = tagged(read_tx(1, Priority::poll), bench.recorder, "poll");
    poll.retry_allowed = false;
    bench.worker->submit(std::move(poll));
    REQUIRE(run_until(bench.io, [&] { return bench.device.requests().size() == 1; }));

    Transaction command = tagged(write_tx(2, 0x0010, 1), bench.recorder, "command");
    command.deadline = fe::Clock::now() + 5ms;
    bench.worker->submit(std::move(command));
    REQUIRE(run_until(bench.io, [&] { return bench.recorder.total() == 2; }));
    run_for(bench.io, 20ms);

    CHECK(bench.recorder.status("command") == OutcomeStatus::expired);
    CHECK(bench.recorder.outcome("command").attempts == 0);
    CHECK(bench.recorder.status("poll") == OutcomeStatus::timeout);
    CHECK(bench.device.count(fp::fc::write_single_register) == 0);
    CHECK(bench.device.requests().size() == 1);
    CHECK(bench.device.unframed_bytes() == 0);
}

TEST_CASE("worker: a write that times out is sent once; a read is retried per read_retries") {
    Bench bench(Bench::short_timing(), 2);
    bench.start();
    bench.device.script.silent = {fp::fc::write_single_register, fp::fc::write_multiple_registers,
                                  fp::fc::read_holding_registers};
    Transaction single = tagged(write_tx(1, 0x0010, 5), bench.recorder, "fc06");
    single.retry_allowed = true;  // must not matter: writes are never retried
    bench.worker->submit(std::move(single));
    bench.worker->submit(tagged(write_multiple_tx(1, 0x0020, {1, 2, 3}), bench.recorder, "fc16"));
    bench.worker->submit(tagged(read_tx(2, Priority::on_demand), bench.recorder, "read"));
    REQUIRE(run_until(bench.io, [&] { return bench.recorder.total() == 3; }));

    CHECK(bench.recorder.status("fc06") == OutcomeStatus::timeout);
    CHECK(bench.recorder.outcome("fc06").attempts == 1);
    CHECK(bench.recorder.status("fc16") == OutcomeStatus::timeout);
    CHECK(bench.recorder.outcome("fc16").attempts == 1);
    CHECK(bench.recorder.status("read") == OutcomeStatus::timeout);
    CHECK(bench.recorder.outcome("read").attempts == 3);
    CHECK(bench.device.count(fp::fc::write_single_register) == 1);
    CHECK(bench.device.count(fp::fc::write_multiple_registers) == 1);
    CHECK(bench.device.count(fp::fc::read_holding_registers) == 3);
    CHECK(bench.logs.contains(fe::LogLevel::warning, "write timed out, not retried"));
}

TEST_CASE("worker: a read that is lost once succeeds on its retry") {
    Bench bench;
    bench.start();
    bench.device.script.silent_count = 1;
    bench.worker->submit(tagged(read_tx(1, Priority::poll), bench.recorder, "poll"));
    REQUIRE(run_until(bench.io, [&] { return bench.recorder.total() == 1; }));
    CHECK(bench.recorder.status("poll") == OutcomeStatus::ok);
    CHECK(bench.recorder.outcome("poll").attempts == 2);
    CHECK(bench.device.requests().size() == 2);
}

TEST_CASE("worker: the local echo of a 2-wire adapter is discarded before the reply") {
    fe::LineTimingConfig timing = Bench::short_timing();
    timing.local_echo = true;
    Bench bench(timing);
    bench.start();
    bench.device.script.echo = true;
    bench.worker->submit(tagged(read_tx(1, Priority::poll, 0x0200, 4), bench.recorder, "read"));
    bench.worker->submit(tagged(write_tx(2, 0x0300, 0xBEEF), bench.recorder, "write"));
    REQUIRE(run_until(bench.io, [&] { return bench.recorder.total() == 2; }));
    CHECK(values_of(bench.recorder.outcome("read")).size() == 4);
    CHECK(bench.recorder.status("write") == OutcomeStatus::ok);
    const auto& counters = bench.worker->master().counters();
    CHECK(counters.echo_mismatch == 0);
    CHECK(counters.garbage_bytes == 0);
    CHECK(bench.device.requests().size() == 2);
}

TEST_CASE("worker: garbage ahead of a reply is tolerated") {
    Bench bench;
    bench.start();
    bench.device.script.prefix = {0x00, 0xFF, 0x13, 0x37};
    bench.worker->submit(tagged(read_tx(1, Priority::poll), bench.recorder, "poll"));
    REQUIRE(run_until(bench.io, [&] { return bench.recorder.total() == 1; }));
    CHECK(values_of(bench.recorder.outcome("poll")).size() == 2);
    CHECK(bench.recorder.outcome("poll").attempts == 1);
    CHECK(bench.worker->master().counters().garbage_bytes == 4);
}

TEST_CASE("worker: stray bytes while idle are read and counted, and push the next request out") {
    Bench bench;
    bench.start();
    bench.device.send({0x55, 0xAA, 0x55});
    REQUIRE(run_until(bench.io, [&] { return bench.worker->master().counters().bytes_rx == 3; }));
    CHECK(bench.worker->master().counters().garbage_bytes == 3);
    bench.worker->submit(tagged(read_tx(1, Priority::poll), bench.recorder, "poll"));
    REQUIRE(run_until(bench.io, [&] { return bench.recorder.total() == 1; }));
    CHECK(bench.recorder.status("poll") == OutcomeStatus::ok);
}

}  // namespace
