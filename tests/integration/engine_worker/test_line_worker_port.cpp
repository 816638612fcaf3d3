// The line worker's port life cycle over real pseudo-terminals: the port vanishing
// and returning (reopen with back-off), a port missing at start, stop() and
// destruction with work pending.
#include "pty_device.hpp"

namespace {

using namespace worker_test;

TEST_CASE("worker: the port vanishes, queued work completes line_down, and the reopened port serves again") {
    Bench bench;
    bench.start();
    bench.worker->submit(tagged(read_tx(1, Priority::poll), bench.recorder, "before"));
    REQUIRE(run_until(bench.io, [&] { return bench.recorder.total() == 1; }));
    REQUIRE(bench.recorder.status("before") == OutcomeStatus::ok);

    // A read in flight (the device keeps quiet) and three more queued when the
    // adapter goes away.
    bench.device.script.silent.insert(fp::fc::read_holding_registers);
    bench.worker->submit(tagged(read_tx(1, Priority::poll), bench.recorder, "in-flight"));
    for (int i = 0; i < 3; ++i) {
        bench.worker->submit(tagged(read_tx(2, Priority::poll), bench.recorder, "queued" + std::to_string(i)));
    }
    REQUIRE(run_until(bench.io, [&] { return bench.device.requests().size() == 2; }));
    bench.device.unplug();
    REQUIRE(run_until(bench.io, [&] { return !bench.worker->line_up(); }));
    REQUIRE(run_until(bench.io, [&] { return bench.recorder.total() == 5; }));
    CHECK(bench.recorder.status("in-flight") == OutcomeStatus::line_down);
    for (int i = 0; i < 3; ++i) CHECK(bench.recorder.status("queued" + std::to_string(i)) == OutcomeStatus::line_down);
    CHECK(bench.states == std::vector<bool>{true, false});
    CHECK(bench.logs.contains(fe::LogLevel::error, "line A: read on the port failed: serial port " +
                                                       bench.device.link().string()));
    CHECK(bench.logs.contains(fe::LogLevel::error, "retrying in 20 ms"));

    // While down, a submission completes line_down on the loop, not inside submit().
    bench.worker->submit(tagged(read_tx(1, Priority::poll), bench.recorder, "while-down"));
    CHECK(bench.recorder.calls("while-down") == 0);
    REQUIRE(run_until(bench.io, [&] { return bench.recorder.calls("while-down") == 1; }));
    CHECK(bench.recorder.status("while-down") == OutcomeStatus::line_down);

    // Let a few reopen attempts fail (20, 40, 80 ms), then the adapter returns.
    run_for(bench.io, 160ms);
    CHECK_FALSE(bench.worker->line_up());
    CHECK(bench.logs.contains(fe::LogLevel::warning, "retrying in 80 ms"));
    bench.device.script = DeviceScript{};
    bench.device.plug();
    REQUIRE(run_until(bench.io, [&] { return bench.worker->line_up(); }, 1000ms));
    CHECK(bench.worker->reopens() == 1);
    CHECK(bench.states == std::vector<bool>{true, false, true});
    CHECK(bench.logs.contains(fe::LogLevel::info, "reopened after"));

    bench.worker->submit(tagged(read_tx(2, Priority::poll, 0x0040, 1), bench.recorder, "after"));
    REQUIRE(run_until(bench.io, [&] { return bench.recorder.calls("after") == 1; }));
    CHECK(values_of(bench.recorder.outcome("after")) == std::vector<std::uint16_t>{PtyDevice::value_at(0x40)});
    CHECK(bench.recorder.total() == 7);
}

TEST_CASE("worker: a port missing at start is retried until it appears") {
    TempDir dir;
    asio::io_context io;
    LogCapture logs;
    Recorder recorder;
    std::vector<bool> states;
    const auto link = dir.path() / "ttyLATE";
    fe::LineWorkerConfig config;
    config.name = "B";
    config.timing.response_timeout = 30ms;
    config.reopen_initial = 10ms;
    config.reopen_max = 40ms;
    fe::SerialSettings settings;
    settings.path = link.string();
    fe::LineWorker worker(io, config, std::make_unique<fe::PosixSerialPort>(settings), logs.sink());
    worker.scheduler().add_device(0, fe::DeviceLimits{});
    worker.set_state_callback([&](bool up, fe::TimePoint) { states.push_back(up); });
    worker.start();
    CHECK_FALSE(worker.line_up());
    CHECK(states == std::vector<bool>{false});
    CHECK(logs.contains(fe::LogLevel::error, "line B: cannot open " + link.string()));

    run_for(io, 50ms);
    PtyDevice device(io, link);
    REQUIRE(run_until(io, [&] { return worker.line_up(); }, 1000ms));
    CHECK(worker.reopens() == 1);
    // The open is logged with what the driver said to the low-latency request.
    CHECK(logs.contains(fe::LogLevel::info, "low latency: not supported by the driver"));
    worker.submit(tagged(read_tx(1, Priority::poll), recorder, "poll"));
    REQUIRE(run_until(io, [&] { return recorder.total() == 1; }));
    CHECK(recorder.status("poll") == OutcomeStatus::ok);
    worker.stop();
}

TEST_CASE("worker: stop() completes everything cancelled exactly once and closes the port") {
    Bench bench;
    bench.start();
    bench.device.script.silent.insert(fp::fc::read_holding_registers);
    Transaction in_flight = tagged(read_tx(1, Priority::poll), bench.recorder, "in-flight");
    in_flight.retry_allowed = false;
    bench.worker->submit(std::move(in_flight));
    REQUIRE(run_until(bench.io, [&] { return bench.device.requests().size() == 1; }));
    for (int i = 0; i < 4; ++i) {
        bench.worker->submit(tagged(read_tx(static_cast<std::uint8_t>(1 + i % 2), Priority::poll),
                                    bench.recorder, "queued" + std::to_string(i)));
    }
    bench.worker->submit(tagged(write_tx(2, 1, 1), bench.recorder, "command"));

    bench.worker->stop();
    // The request in flight went out: the device may have acted, so it is not
    // "cancelled"; everything else never went out.
    CHECK(bench.recorder.status("in-flight") == OutcomeStatus::timeout);
    for (int i = 0; i < 4; ++i) CHECK(bench.recorder.status("queued" + std::to_string(i)) == OutcomeStatus::cancelled);
    CHECK(bench.recorder.status("command") == OutcomeStatus::cancelled);
    CHECK_FALSE(bench.worker->line_up());
    CHECK(bench.states == std::vector<bool>{true, false});

    bench.worker->stop();  // idempotent
    bench.worker->submit(tagged(read_tx(1, Priority::poll), bench.recorder, "after-stop"));
    CHECK(bench.recorder.calls("after-stop") == 0);  // never inside submit()
    run_for(bench.io, 50ms);
    CHECK(bench.recorder.status("after-stop") == OutcomeStatus::cancelled);
    CHECK(bench.recorder.total() == 7);
    CHECK(bench.device.requests().size() == 1);  // nothing went out after stop
    CHECK(bench.states == std::vector<bool>{true, false});
}

TEST_CASE("worker: a completion may stop the worker") {
    Bench bench;
    bench.start();
    bench.worker->submit(tagged(read_tx(2, Priority::poll), bench.recorder, "second"));
    Transaction first = read_tx(1, Priority::command);
    first.on_done = [&](const fe::Outcome&) { bench.worker->stop(); };
    bench.worker->submit(std::move(first));
    REQUIRE(run_until(bench.io, [&] { return bench.recorder.total() == 1; }));
    CHECK(bench.recorder.status("second") == OutcomeStatus::cancelled);
    run_for(bench.io, 20ms);
    CHECK(bench.device.requests().size() == 1);
}

TEST_CASE("worker: destroyed with waits pending, the loop runs on without touching it") {
    TempDir dir;
    asio::io_context io;
    PtyDevice device(io, dir.path() / "ttyGONE");
    Recorder recorder;
    {
        fe::LineWorkerConfig config;
        config.name = "C";
        fe::SerialSettings settings;
        settings.path = device.link().string();
        fe::LineWorker worker(io, config, std::make_unique<fe::PosixSerialPort>(settings));
        worker.scheduler().add_device(0, fe::DeviceLimits{});
        worker.start();
        device.script.silent.insert(fp::fc::read_holding_registers);
        worker.submit(tagged(read_tx(1, Priority::poll), recorder, "in-flight"));
        worker.submit(tagged(read_tx(1, Priority::poll), recorder, "queued"));
        REQUIRE(run_until(io, [&] { return device.requests().size() == 1; }));
        worker.submit(tagged(read_tx(1, Priority::poll), recorder, "posted"));
        // Destroyed without stop(): the destructor stops it.
    }
    CHECK(recorder.total() == 3);
    CHECK(recorder.calls("in-flight") == 1);
    CHECK(recorder.status("queued") == OutcomeStatus::cancelled);
    CHECK(recorder.status("posted") == OutcomeStatus::cancelled);
    device.send({0x01, 0x02});  // readable, but nobody waits any more
    run_for(io, 30ms);
    CHECK(recorder.total() == 3);
}

}  // namespace
