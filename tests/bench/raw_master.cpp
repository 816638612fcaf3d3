#include "raw_master.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "engine/line_timing.hpp"
#include "percentile.hpp"
#include "process_cpu.hpp"
#include "protocol/rtu_frame.hpp"

namespace fieldbridge::bench {
namespace {

using Clock = std::chrono::steady_clock;

/// Owns the pty file descriptor.
class RawPort {
public:
    explicit RawPort(const std::string& path) : fd_(::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK)) {
        if (fd_ < 0) throw std::runtime_error("raw master: cannot open " + path + ": " + std::strerror(errno));
        termios tio{};
        if (::tcgetattr(fd_, &tio) == 0) {
            ::cfmakeraw(&tio);
            static_cast<void>(::tcsetattr(fd_, TCSANOW, &tio));
        }
    }
    ~RawPort() { ::close(fd_); }
    RawPort(const RawPort&) = delete;
    RawPort& operator=(const RawPort&) = delete;
    [[nodiscard]] int fd() const noexcept { return fd_; }

private:
    int fd_;
};

void sleep_until(Clock::time_point until) {
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(until.time_since_epoch()).count();
    const timespec ts{static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
    while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
    }
}

}  // namespace

RawMasterResult run_raw_master(const RawMasterSetup& setup) {
    // The same timer slack the line worker sets (engine/line_worker.cpp).
    ::prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
    const engine::LineTiming timing(engine::CharacterFormat{setup.baud, 8, false, 1});
    constexpr std::size_t reply_size = LoadShape::read_reply_bytes();
    const auto bound = timing.wire_time(LoadShape::read_request_bytes()) + setup.turnaround +
                       timing.wire_time(reply_size);

    RawPort port(setup.path);
    RawMasterResult result;
    result.spin_lead_us = std::chrono::duration<double, std::micro>(setup.spin_lead).count();
    result.reply_bound_ms = std::chrono::duration<double, std::milli>(bound).count();
    const CpuTimes cpu0 = process_cpu();
    const auto start = Clock::now();
    const auto end = start + std::chrono::duration_cast<Clock::duration>(setup.duration);
    std::array<std::uint8_t, 256> buffer{};
    std::vector<double> reply_ms;
    std::vector<double> silence_us;
    std::uint64_t n = 0;
    Clock::time_point last_reply{};
    while (Clock::now() < end) {
        const ShapeRead read = setup.shape.read(n++);
        const std::array<std::uint8_t, 5> pdu{read.function, static_cast<std::uint8_t>(read.address >> 8),
                                              static_cast<std::uint8_t>(read.address & 0xFF),
                                              static_cast<std::uint8_t>(read.count >> 8),
                                              static_cast<std::uint8_t>(read.count & 0xFF)};
        const protocol::Bytes request = protocol::encode_rtu(setup.shape.bus_address(read.device), pdu);
        const auto sent = Clock::now();
        if (last_reply != Clock::time_point{}) {
            silence_us.push_back(std::chrono::duration<double, std::micro>(sent - last_reply).count());
        }
        if (::write(port.fd(), request.data(), request.size()) != static_cast<ssize_t>(request.size())) {
            throw std::runtime_error("raw master: write to " + setup.path + " failed: " + std::strerror(errno));
        }
        std::size_t got = 0;
        while (got < reply_size) {
            pollfd readable{port.fd(), POLLIN, 0};
            if (::poll(&readable, 1, 100) <= 0) break;
            const ssize_t count = ::read(port.fd(), buffer.data() + got, buffer.size() - got);
            if (count > 0) got += static_cast<std::size_t>(count);
        }
        last_reply = Clock::now();
        if (got == reply_size) {
            ++result.transactions;
            if (last_reply - sent < bound) ++result.early_replies;
            reply_ms.push_back(std::chrono::duration<double, std::milli>(last_reply - sent).count());
        } else {
            ++result.timeouts;
        }
        const auto silence_end = last_reply + timing.t3_5();
        if (setup.spin_lead > std::chrono::nanoseconds::zero()) {
            if (silence_end - Clock::now() > setup.spin_lead) sleep_until(silence_end - setup.spin_lead);
            while (Clock::now() < silence_end) {
#if defined(__x86_64__) || defined(__i386__)
                __builtin_ia32_pause();
#endif
            }
        } else {
            sleep_until(silence_end);
        }
    }
    const CpuTimes cpu1 = process_cpu();
    result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    if (result.transactions > 0) {
        const auto count = static_cast<double>(result.transactions);
        result.user_cpu_us = (cpu1.user - cpu0.user) * 1e6 / count;
        result.sys_cpu_us = (cpu1.sys - cpu0.sys) * 1e6 / count;
        std::sort(reply_ms.begin(), reply_ms.end());
        result.reply_min_ms = reply_ms.front();
        result.reply_median_ms = percentile_of_sorted(reply_ms, 0.5);
        result.reply_p99_ms = percentile_of_sorted(reply_ms, 0.99);
    }
    if (!silence_us.empty()) {
        std::sort(silence_us.begin(), silence_us.end());
        result.silence_min_us = silence_us.front();
        result.silence_median_us = percentile_of_sorted(silence_us, 0.5);
        result.silence_p99_us = percentile_of_sorted(silence_us, 0.99);
    }
    return result;
}

}  // namespace fieldbridge::bench
