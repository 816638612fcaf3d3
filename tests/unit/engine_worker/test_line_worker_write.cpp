// Non-blocking writes: a driver that takes the request a few bytes at a time, and
// sometimes nothing, gets all of it, in order, and the reply wait starts only after
// the last piece. The port is a SerialPort over a socketpair, so readiness is real.
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>

#include "worker_test_support.hpp"

namespace {

using namespace worker_test;

class ChunkedPort final : public fe::SerialPort {
public:
    explicit ChunkedPort(std::size_t chunk) : chunk_(chunk) { settings_.path = "chunked"; }
    ~ChunkedPort() override {
        close();
        if (peer_ >= 0) ::close(peer_);
    }

    void open() override {
        int fds[2] = {-1, -1};
        REQUIRE(::socketpair(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK, 0, fds) == 0);
        fd_ = fds[0];
        peer_ = fds[1];
    }
    void close() noexcept override {
        if (fd_ >= 0) ::close(fd_);
        fd_ = -1;
    }
    [[nodiscard]] bool is_open() const noexcept override { return fd_ >= 0; }
    [[nodiscard]] int native_handle() const noexcept override { return fd_; }
    [[nodiscard]] std::size_t write_some(fp::ByteView bytes) override {
        ++write_calls;
        // Every other call the driver's buffer is "full".
        accept_ = !accept_;
        if (!accept_) return 0;
        const ssize_t n = ::send(fd_, bytes.data(), std::min(chunk_, bytes.size()), 0);
        if (n < 0) throw fe::SerialPortError("chunked: send failed");
        return static_cast<std::size_t>(n);
    }
    [[nodiscard]] std::size_t read_some(std::span<std::uint8_t> buffer) override {
        ++read_calls;
        const ssize_t n = ::recv(fd_, buffer.data(), buffer.size(), MSG_DONTWAIT);
        if (n > 0) return static_cast<std::size_t>(n);
        if (n == 0) throw fe::SerialPortError("chunked: peer closed");
        if (errno == EAGAIN) return 0;
        throw fe::SerialPortError("chunked: recv failed");
    }
    void discard_input() noexcept override {}
    [[nodiscard]] const fe::SerialSettings& settings() const noexcept override { return settings_; }

    /// The device's end of the line.
    [[nodiscard]] int peer() const { return peer_; }
    std::size_t write_calls = 0;
    std::size_t read_calls = 0;  ///< including those that found nothing

private:
    std::size_t chunk_;
    fe::SerialSettings settings_;
    int fd_ = -1;
    int peer_ = -1;
    bool accept_ = false;
};

/// A started worker "W" with one device (address 1) on a ChunkedPort taking
/// @p chunk bytes per write, and the device's side of the line.
struct ChunkedLine {
    explicit ChunkedLine(std::size_t chunk, fe::LineWorkerConfig config = {})
        : owned(std::make_unique<ChunkedPort>(chunk)),
          port(*owned),
          worker(io, named(std::move(config)), std::move(owned)) {
        worker.scheduler().add_device(0, fe::DeviceLimits{});
        worker.start();
        REQUIRE(worker.line_up());
    }
    static fe::LineWorkerConfig named(fe::LineWorkerConfig config) {
        config.name = "W";
        return config;
    }
    /// True when the device side received one whole read request (8 bytes).
    bool read_request_arrived() {
        std::array<std::uint8_t, 64> buffer{};
        return ::recv(port.peer(), buffer.data(), buffer.size(), MSG_DONTWAIT) == 8;
    }
    /// Answers a read whole, as the device would.
    void answer_read() {
        const Bytes reply =
            fp::encode_rtu(1, fp::encode_response(fp::ReadRegistersResponse{fp::fc::read_holding_registers, {7, 8}}));
        REQUIRE(::send(port.peer(), reply.data(), reply.size(), 0) == static_cast<ssize_t>(reply.size()));
    }

    asio::io_context io;
    std::unique_ptr<ChunkedPort> owned;  ///< moved into the worker
    ChunkedPort& port;
    fe::LineWorker worker;
};

TEST_CASE("worker: a request the driver takes in pieces goes out whole, then the reply is awaited") {
    ChunkedLine line(3);
    auto& io = line.io;
    auto& port = line.port;
    auto& worker = line.worker;

    Recorder recorder;
    const std::vector<std::uint16_t> values{1, 2, 3, 4, 5, 6, 7};
    worker.submit(tagged(write_multiple_tx(1, 0x0020, values), recorder, "fc16"));
    const Bytes expected =
        fp::encode_rtu(1, fp::encode_request(fp::WriteMultipleRegistersRequest{0x0020, values}));

    Bytes received;
    REQUIRE(run_until(io, [&] {
        std::array<std::uint8_t, 64> buffer{};
        const ssize_t n = ::recv(port.peer(), buffer.data(), buffer.size(), MSG_DONTWAIT);
        if (n > 0) received.insert(received.end(), buffer.begin(), buffer.begin() + n);
        return received.size() >= expected.size();
    }));
    CHECK(received == expected);
    CHECK(port.write_calls >= 2 * (expected.size() / 3));
    CHECK(worker.master().state() == fe::MasterState::awaiting_reply);
    CHECK(worker.master().counters().requests == 1);

    const Bytes reply = fp::encode_rtu(
        1, fp::encode_response(fp::WriteMultipleResponse{fp::fc::write_multiple_registers, 0x0020, 7}));
    REQUIRE(::send(port.peer(), reply.data(), reply.size(), 0) == static_cast<ssize_t>(reply.size()));
    REQUIRE(run_until(io, [&] { return recorder.total() == 1; }));
    CHECK(recorder.status("fc16") == OutcomeStatus::ok);
    CHECK(recorder.outcome("fc16").attempts == 1);
    worker.stop();
}

TEST_CASE("worker: back-to-back transactions read the port about once each, not before every decision") {
    // The worker reads when the reactor reports the port readable. Right after such a
    // report (readiness or wake timer), reading again before the write or before
    // judging a timeout cannot find anything new: it would cost a system call per
    // transaction for nothing (docs/performance.md). 8 transactions with whole
    // replies: one read each, plus a few for the start and the posted submissions.
    ChunkedLine line(256);
    auto& io = line.io;
    auto& port = line.port;
    auto& worker = line.worker;

    Recorder recorder;
    constexpr int transactions = 8;
    for (int i = 0; i < transactions; ++i) {
        worker.submit(tagged(read_tx(1, Priority::on_demand), recorder, "read" + std::to_string(i)));
    }
    const std::size_t reads_before = port.read_calls;
    std::size_t answered = 0;
    REQUIRE(run_until(io, [&] {
        if (line.read_request_arrived()) {  // one whole request: answer it whole
            line.answer_read();
            ++answered;
        }
        return recorder.total() == transactions;
    }));
    CHECK(answered == transactions);
    for (int i = 0; i < transactions; ++i) CHECK(recorder.status("read" + std::to_string(i)) == OutcomeStatus::ok);
    const std::size_t reads = port.read_calls - reads_before;
    INFO("read_some calls for " << transactions << " transactions: " << reads);
    CHECK(reads >= transactions);
    CHECK(reads <= transactions + 4);
    worker.stop();
}

TEST_CASE("worker: after many answered requests, a reply timeout is judged at its deadline, not late or early") {
    // Long waits (response timeouts) share a timer that is not re-set for every
    // request: it may wake the worker early, which then waits on. The timeout must
    // still be decided at written + wire time + response_timeout.
    fe::LineWorkerConfig config;
    config.timing.response_timeout = 60ms;
    ChunkedLine line(256, config);
    auto& io = line.io;
    auto& worker = line.worker;

    Recorder recorder;
    constexpr int answered_first = 8;  // within the default queue limit
    for (int i = 0; i < answered_first; ++i) {
        worker.submit(tagged(read_tx(1, Priority::on_demand), recorder, "read" + std::to_string(i)));
    }
    int requests_seen = 0;
    fe::TimePoint last_request_seen{};
    REQUIRE(run_until(io, [&] {
        if (line.read_request_arrived()) {
            ++requests_seen;
            last_request_seen = fe::Clock::now();
            if (requests_seen <= answered_first) {
                line.answer_read();
                if (requests_seen == answered_first) {
                    Transaction last = read_tx(1, Priority::on_demand);
                    last.retry_allowed = false;  // one request on the wire, one timeout
                    worker.submit(tagged(std::move(last), recorder, "unanswered"));
                }
            }
        }
        return recorder.calls("unanswered") == 1;
    }));
    REQUIRE(requests_seen == answered_first + 1);
    CHECK(recorder.status("unanswered") == OutcomeStatus::timeout);
    const auto waited = recorder.outcome("unanswered").finished - last_request_seen;
    INFO("timeout judged " << std::chrono::duration_cast<std::chrono::microseconds>(waited).count()
                           << " us after the request was seen");
    CHECK(waited >= 60ms);
    // A functional bound, not a performance figure: a timeout judged on a stale
    // wake-up of the shared timer comes a whole response_timeout (60 ms) late; the
    // 40 ms cover the wire time of 8 bytes (0.7 ms) and a loaded sanitizer build.
    CHECK(waited < 60ms + 40ms);
    worker.stop();
}

}  // namespace
