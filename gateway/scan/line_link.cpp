#include "scan/line_link.hpp"

#include <poll.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>

namespace fieldbridge::scan {

namespace {

using engine::Clock;

/// A write the driver does not take within this long means the port is stuck
/// (flow control, a dead USB adapter): fail instead of hanging the scan.
constexpr auto write_stall_limit = std::chrono::seconds{2};

[[nodiscard]] timespec to_timespec(engine::Duration d) {
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(d);
    const auto s = std::chrono::duration_cast<std::chrono::seconds>(ns);
    timespec ts{};
    ts.tv_sec = static_cast<std::time_t>(s.count());
    ts.tv_nsec = static_cast<long>((ns - s).count());
    return ts;
}

/// ppoll() on @p fd for @p events until @p until; true when ready.
[[nodiscard]] bool wait_for(int fd, short events, engine::TimePoint until, const std::string& port) {
    for (;;) {
        const auto left = until - Clock::now();
        if (left <= engine::Duration::zero()) {
            return false;
        }
        pollfd p{fd, events, 0};
        const timespec timeout = to_timespec(left);
        const int n = ::ppoll(&p, 1, &timeout, nullptr);
        if (n > 0) {
            return true;  // readable, writable, or an error the next read/write reports
        }
        if (n < 0 && errno != EINTR) {
            throw engine::SerialPortError("serial port " + port + ": waiting for it failed: " +
                                          std::strerror(errno));
        }
    }
}

}  // namespace

LineLink::LineLink(engine::SerialPort& port, engine::LineTimingConfig timing, engine::LogSink log)
    : port_(port), master_(port.settings().path, timing, std::move(log)) {
    master_.reset(Clock::now());
}

void LineLink::wait_and_read(engine::TimePoint until, protocol::Bytes* sink) {
    if (!wait_for(port_.native_handle(), POLLIN, until, port_.settings().path)) {
        return;
    }
    std::array<std::uint8_t, 256> buffer{};
    for (;;) {
        const std::size_t n = port_.read_some(buffer);
        if (n == 0) {
            return;
        }
        const protocol::ByteView bytes(buffer.data(), n);
        master_.on_bytes(bytes, Clock::now());
        if (sink != nullptr) {
            sink->insert(sink->end(), bytes.begin(), bytes.end());
        }
    }
}

void LineLink::write_all(protocol::ByteView bytes) {
    const auto give_up = Clock::now() + write_stall_limit;
    while (!bytes.empty()) {
        const std::size_t n = port_.write_some(bytes);
        bytes = bytes.subspan(n);
        if (!bytes.empty() && !wait_for(port_.native_handle(), POLLOUT, give_up, port_.settings().path)) {
            throw engine::SerialPortError("serial port " + port_.settings().path +
                                          ": the driver took no data for 2 s; check the adapter and flow control");
        }
    }
}

engine::Outcome LineLink::transact(engine::Payload payload, std::uint8_t address, protocol::Bytes* received) {
    engine::Transaction transaction;
    transaction.address = address;
    transaction.payload = std::move(payload);
    transaction.priority = engine::Priority::on_demand;
    transaction.id = next_id_++;
    master_.start(std::move(transaction), Clock::now());
    // Bounded: the master decides a timeout by its own deadlines, so every Wait ends.
    for (;;) {
        engine::LineAction action = master_.next_action(Clock::now());
        if (auto* wait = std::get_if<engine::line_action::Wait>(&action)) {
            wait_and_read(wait->until, received);
        } else if (auto* write = std::get_if<engine::line_action::Write>(&action)) {
            write_all(write->bytes);
            master_.on_written(Clock::now());
        } else if (auto* done = std::get_if<engine::line_action::Finished>(&action)) {
            return std::move(done->outcome);
        } else {
            throw std::logic_error("line master idle while a scan request was in flight");
        }
    }
}

protocol::Bytes LineLink::listen(engine::Duration quiet, engine::Duration limit) {
    protocol::Bytes received;
    const auto start = Clock::now();
    const auto hard_end = start + quiet + limit;
    auto quiet_end = start + quiet;
    while (Clock::now() < quiet_end) {
        const std::size_t before = received.size();
        wait_and_read(std::min(quiet_end, hard_end), &received);
        if (received.size() != before) {
            quiet_end = std::min(Clock::now() + quiet, hard_end);
        }
    }
    return received;
}

}  // namespace fieldbridge::scan
