#include "scan/line_link.hpp"

#include <poll.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace fieldbridge::scan {

namespace {

using engine::Clock;
namespace line_event = engine::line_event;

/// A write the driver does not take within this long means the port is stuck
/// (flow control, a dead USB adapter): fail instead of hanging the scan.
constexpr auto write_stall_limit = std::chrono::seconds{2};

/// The one device the scan's requests go to: the address travels in the request.
constexpr engine::DeviceIndex scan_device = 0;

[[nodiscard]] timespec to_timespec(engine::Duration d) {
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(d);
    const auto s = std::chrono::duration_cast<std::chrono::seconds>(ns);
    timespec ts{};
    ts.tv_sec = static_cast<std::time_t>(s.count());
    ts.tv_nsec = static_cast<long>((ns - s).count());
    return ts;
}

/// ppoll() on @p fd for @p events until @p until (at least once, so a due deadline
/// still sees what is ready); true when ready.
[[nodiscard]] bool wait_for(int fd, short events, engine::TimePoint until, const std::string& port) {
    for (;;) {
        const auto left = std::max(until - Clock::now(), engine::Duration::zero());
        pollfd p{fd, events, 0};
        const timespec timeout = to_timespec(left);
        const int n = ::ppoll(&p, 1, &timeout, nullptr);
        if (n > 0) {
            return true;  // readable, writable, or an error the next read/write reports
        }
        if (n == 0) {
            return false;
        }
        if (errno != EINTR) {
            throw engine::SerialPortError("serial port " + port + ": waiting for it failed: " + std::strerror(errno));
        }
    }
}

[[nodiscard]] engine::LineCoreConfig core_config(const engine::SerialPort& port, engine::LineTimingConfig timing) {
    engine::LineCoreConfig config;
    config.name = port.settings().path;
    config.timing = timing;
    return config;
}

/// A scan asks every address once or a few times: no retry, never offline (the
/// scheduler's offline policy is for devices known to exist).
[[nodiscard]] engine::DeviceLimits scan_limits() {
    engine::DeviceLimits limits;
    limits.queue_limit = 1;
    limits.read_retries = 0;
    limits.offline_after = std::numeric_limits<unsigned>::max();
    return limits;
}

}  // namespace

LineLink::LineLink(engine::SerialPort& port, engine::LineTimingConfig timing, engine::LogSink log)
    : port_(port),
      core_(core_config(port, timing), port.settings().path, log),
      delivery_(port.settings().path, log) {
    core_.scheduler().add_device(scan_device, scan_limits());
    feed(line_event::Start{});
}

void LineLink::feed(engine::LineEvent&& event) {
    while (true) {
        const engine::LineStep step = core_.handle(Clock::now(), std::move(event));
        apply(step);
        delivery_.deliver(core_.scheduler());
        switch (step.next) {
            case engine::LineNext::none:
                return;
            case engine::LineNext::resume:
            case engine::LineNext::tick:
                event = line_event::Resume{};
                break;
            case engine::LineNext::spin:
                // Only with a spin lead, which the scan does not set: busy-wait anyway.
                while (Clock::now() < step.spin_until) {
                }
                event = line_event::Resume{};
                break;
            case engine::LineNext::open:
                // The caller opened the port: the scan needs it to itself and says so
                // before the link exists. A failure here is the caller's to report.
                if (!port_.is_open()) port_.open();
                event = line_event::Opened{"opened for the scan"};
                break;
            case engine::LineNext::read:
                event = read();
                break;
            case engine::LineNext::write:
                event = write(step.write);
                break;
        }
    }
}

void LineLink::apply(const engine::LineStep& step) {
    // Readiness is polled in wait_for_event(); the port is never closed or reopened
    // here (a failure throws to the caller).
    if (step.exact_wake) exact_at_ = step.exact_wake;
    if (step.lazy_wake) lazy_at_ = step.lazy_wake;
    if (step.watch_writable) watch_writable_ = true;
    if (step.post_drive) {
        // Run from feed()'s caller: there is no loop to post to, and the core asks
        // for a drive only between events.
        pending_drive_ = true;
    }
}

engine::LineEvent LineLink::read() {
    const std::size_t n = port_.read_some(buffer_);  // throws SerialPortError: the scan stops
    const protocol::ByteView bytes(buffer_.data(), n);
    if (sink_ != nullptr) sink_->insert(sink_->end(), bytes.begin(), bytes.end());
    return line_event::BytesRead{bytes, n == buffer_.size()};
}

engine::LineEvent LineLink::write(protocol::ByteView bytes) {
    std::size_t sent = 0;
    while (sent < bytes.size()) {
        const std::size_t n = port_.write_some(bytes.subspan(sent));
        if (n == 0) return line_event::WriteBlocked{sent};
        sent += n;
    }
    return line_event::Written{};
}

void LineLink::wait_for_event() {
    if (pending_drive_) {
        pending_drive_ = false;
        feed(line_event::Drive{});
        return;
    }
    if (watch_writable_) {
        watch_writable_ = false;
        if (!wait_for(port_.native_handle(), POLLOUT, Clock::now() + write_stall_limit, port_.settings().path)) {
            throw engine::SerialPortError("serial port " + port_.settings().path +
                                          ": the driver took no data for 2 s; check the adapter and flow control");
        }
        feed(line_event::Writable{});
        return;
    }
    if (!exact_at_ && !lazy_at_) {
        throw std::logic_error("scan link " + port_.settings().path +
                               ": nothing to wait for while a scan request is in flight (line core bug)");
    }
    const bool exact = exact_at_ && (!lazy_at_ || *exact_at_ <= *lazy_at_);
    const engine::TimePoint until = exact ? *exact_at_ : *lazy_at_;
    if (wait_for(port_.native_handle(), POLLIN, until, port_.settings().path)) {
        feed(line_event::Readable{});
        return;
    }
    (exact ? exact_at_ : lazy_at_).reset();
    feed(line_event::TimerFired{exact ? engine::WakeTimer::exact : engine::WakeTimer::lazy});
}

engine::Outcome LineLink::transact(engine::Payload payload, std::uint8_t address, protocol::Bytes* received) {
    std::optional<engine::Outcome> outcome;
    engine::Transaction transaction;
    transaction.device = scan_device;
    transaction.address = address;
    transaction.payload = std::move(payload);
    transaction.priority = engine::Priority::on_demand;
    transaction.retry_allowed = true;  // reads: a timeout is not a write to warn about
    transaction.on_done = [&outcome](const engine::Outcome& done) { outcome = done; };
    sink_ = received;
    feed(line_event::Submit{std::move(transaction)});
    // Bounded: the master decides a timeout by its own deadlines, so every wait ends.
    while (!outcome) wait_for_event();
    sink_ = nullptr;
    return std::move(*outcome);
}

protocol::Bytes LineLink::listen(engine::Duration quiet, engine::Duration limit) {
    protocol::Bytes received;
    sink_ = &received;
    const auto start = Clock::now();
    const auto hard_end = start + quiet + limit;
    auto quiet_end = start + quiet;
    while (Clock::now() < quiet_end) {
        const std::size_t before = received.size();
        if (wait_for(port_.native_handle(), POLLIN, std::min(quiet_end, hard_end), port_.settings().path)) {
            feed(line_event::Readable{});
        }
        if (received.size() != before) {
            quiet_end = std::min(Clock::now() + quiet, hard_end);
        }
    }
    sink_ = nullptr;
    return received;
}

}  // namespace fieldbridge::scan
