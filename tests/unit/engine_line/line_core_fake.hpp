#pragma once
/// @file line_core_fake.hpp
/// The shell of the line core tests: a LineCore on a fake clock with a scripted port,
/// answering the core's questions the way the line worker does, and the read every
/// test sends. Shared by test_line_core.cpp and test_line_core_precise.cpp.
#include <doctest/doctest.h>

#include <deque>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "line_test_support.hpp"

namespace line_core_test {

using namespace line_test;
using fe::OutcomeStatus;
namespace ev = fe::line_event;

struct FakeLine {
    explicit FakeLine(fe::LineCoreConfig config = named("L"))
        : core(std::move(config), "/dev/ttyFAKE", sink()), delivery("L", sink()) {
        core.scheduler().add_device(0, fe::DeviceLimits{});
        core.scheduler().add_device(1, fe::DeviceLimits{});
    }
    static fe::LineCoreConfig named(std::string name) {
        fe::LineCoreConfig config;
        config.name = std::move(name);
        config.reopen_initial = 100ms;
        config.reopen_max = 350ms;
        return config;
    }
    fe::LogSink sink() {
        return fe::LogSink{[this](fe::LogLevel level, std::string_view m) { logs.emplace_back(level, m); },
                           fe::LogLevel::info};
    }
    [[nodiscard]] bool logged(fe::LogLevel level, const std::string& text) const {
        for (const auto& [l, m] : logs) {
            if (l == level && m.find(text) != std::string::npos) return true;
        }
        return false;
    }

    // ---- the shell ----------------------------------------------------------------

    void feed(fe::LineEvent&& event) {
        while (true) {
            const fe::LineStep step = core.handle(now, std::move(event));
            if (step.close_port) ++closes;
            if (step.cancel_timers) exact_at = lazy_at = reopen_at = std::nullopt;
            if (step.exact_wake) {
                exact_at = step.exact_wake;
                ++exact_sets;
            }
            if (step.lazy_wake) {
                lazy_at = step.lazy_wake;
                ++lazy_sets;
            }
            if (step.reopen_at) reopen_at = step.reopen_at;
            if (step.watch_writable) watching_writable = true;
            if (step.post_drive) drive_posted = true;
            delivery.deliver(core.scheduler());
            if (step.line_up) states.push_back(*step.line_up);
            switch (step.next) {
                case fe::LineNext::none: return;
                case fe::LineNext::resume:
                case fe::LineNext::tick: event = ev::Resume{}; break;
                case fe::LineNext::spin:
                    // The clock seam runs on while the shell spins; bytes may arrive.
                    ++spins;
                    REQUIRE(step.spin_until > now);
                    REQUIRE(step.spin_until - now <= core.config().spin_lead);
                    now = step.spin_until;
                    for (Bytes& bytes : arrive_during_spin) input.push_back(std::move(bytes));
                    arrive_during_spin.clear();
                    event = ev::Resume{};
                    break;
                case fe::LineNext::open:
                    if (open_pending) {
                        event = ev::OpenPending{};
                    } else if (open_failure) {
                        event = ev::OpenFailed{*open_failure};
                    } else {
                        event = ev::Opened{"low latency: test"};
                    }
                    break;
                case fe::LineNext::read: event = read(); break;
                case fe::LineNext::write: event = write(step.write); break;
            }
        }
    }

    fe::LineEvent read() {
        ++reads;
        if (read_failure) return ev::PortFailed{"read", *read_failure};
        read_buffer.clear();
        if (!input.empty()) {
            read_buffer = input.front();
            input.pop_front();
        }
        return ev::BytesRead{read_buffer, !input.empty() && full_reads};
    }

    fe::LineEvent write(fp::ByteView bytes) {
        const std::size_t n = std::min(bytes.size(), write_capacity);
        written.insert(written.end(), bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n));
        last_write_at = now;
        write_capacity -= n;
        if (n < bytes.size()) return ev::WriteBlocked{n};
        return ev::Written{};
    }

    /// Posted work first, then the timers due, in time order, until @p until.
    void advance_to(TimePoint until) {
        while (true) {
            if (drive_posted) {
                drive_posted = false;
                feed(ev::Drive{});
                continue;
            }
            std::optional<TimePoint> next;
            for (const auto& at : {exact_at, lazy_at, reopen_at}) {
                if (at && (!next || *at < *next)) next = at;
            }
            if (!next || *next > until) break;
            now = std::max(now, *next);
            if (exact_at == next) {
                exact_at.reset();
                feed(ev::TimerFired{fe::WakeTimer::exact});
            } else if (lazy_at == next) {
                lazy_at.reset();
                feed(ev::TimerFired{fe::WakeTimer::lazy});
            } else {
                reopen_at.reset();
                feed(ev::ReopenDue{});
            }
        }
        now = std::max(now, until);
    }
    void advance(Duration by) { advance_to(now + by); }

    void start() {
        feed(ev::Start{});
        advance(0ms);
    }
    void submit(Transaction t, const std::string& tag) {
        feed(ev::Submit{tagged(std::move(t), recorder, tag)});
    }
    /// The readiness report for bytes that arrived: one read, then a drive (polled).
    void arrive(Bytes bytes) {
        input.push_back(std::move(bytes));
        feed(ev::Readable{});
        advance(0ms);
    }
    /// The written bytes since the last call.
    Bytes take_written() { return std::exchange(written, {}); }

    TimePoint now = t0;
    std::vector<std::pair<fe::LogLevel, std::string>> logs;
    fe::LineCore core;
    fe::LineDelivery delivery;
    Recorder recorder;
    std::vector<bool> states;

    std::deque<Bytes> input;  ///< what each read returns, one chunk per read
    bool full_reads = true;   ///< a read reports the buffer full while more chunks wait
    Bytes read_buffer;
    Bytes written;
    std::size_t write_capacity = std::numeric_limits<std::size_t>::max();
    std::optional<std::string> open_failure;
    bool open_pending = false;  ///< answer open with OpenPending (a TCP connect runs)
    std::optional<std::string> read_failure;
    TimePoint last_write_at{};
    std::vector<Bytes> arrive_during_spin;  ///< in the port's buffer once the next spin ends
    unsigned spins = 0;
    unsigned reads = 0;
    unsigned closes = 0;
    unsigned exact_sets = 0;
    unsigned lazy_sets = 0;
    bool watching_writable = false;
    bool drive_posted = false;
    std::optional<TimePoint> exact_at;
    std::optional<TimePoint> lazy_at;
    std::optional<TimePoint> reopen_at;
};

inline const Bytes read_request = fp::encode_rtu(
    1, fp::encode_request(fp::ReadRegistersRequest{fp::fc::read_input_registers, 0x0300, 2}));

inline Bytes reply_1() { return read_reply(1, {7, 8}); }

/// Submits a read of device 0 (address 1) and lets it go out.
inline void send_read(FakeLine& line, const std::string& tag, Priority priority = Priority::poll, bool retry = true) {
    Transaction t = read_tx(0, 1, priority);
    t.retry_allowed = retry;
    line.submit(std::move(t), tag);
    line.advance(1ms);
    REQUIRE(line.take_written() == read_request);
}

}  // namespace line_core_test
