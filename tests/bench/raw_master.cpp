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

RawMasterResult run_raw_master(const std::string& path, std::uint8_t address, std::uint16_t reg,
                               std::chrono::duration<double> duration) {
    // The same timer slack the line worker sets (engine/line_worker.cpp).
    ::prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
    const engine::LineTiming timing(engine::CharacterFormat{115200, 8, false, 1});
    const std::array<std::uint8_t, 5> pdu{0x04, static_cast<std::uint8_t>(reg >> 8),
                                          static_cast<std::uint8_t>(reg & 0xFF), 0x00, 0x02};
    const protocol::Bytes request = protocol::encode_rtu(address, pdu);
    constexpr std::size_t reply_size = 9;  // address, 04, count, 2 x 2 bytes, CRC

    RawPort port(path);
    RawMasterResult result;
    const CpuTimes cpu0 = process_cpu();
    const auto start = Clock::now();
    const auto end = start + std::chrono::duration_cast<Clock::duration>(duration);
    std::array<std::uint8_t, 256> buffer{};
    std::vector<double> reply_ms;
    while (Clock::now() < end) {
        const auto sent = Clock::now();
        if (::write(port.fd(), request.data(), request.size()) != static_cast<ssize_t>(request.size())) {
            throw std::runtime_error("raw master: write to " + path + " failed: " + std::strerror(errno));
        }
        std::size_t got = 0;
        while (got < reply_size) {
            pollfd readable{port.fd(), POLLIN, 0};
            if (::poll(&readable, 1, 100) <= 0) break;
            const ssize_t n = ::read(port.fd(), buffer.data() + got, buffer.size() - got);
            if (n > 0) got += static_cast<std::size_t>(n);
        }
        if (got == reply_size) {
            ++result.transactions;
            reply_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - sent).count());
        } else {
            ++result.timeouts;
        }
        sleep_until(Clock::now() + timing.t3_5());
    }
    const CpuTimes cpu1 = process_cpu();
    result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    if (result.transactions > 0) {
        const auto n = static_cast<double>(result.transactions);
        result.user_cpu_us = (cpu1.user - cpu0.user) * 1e6 / n;
        result.sys_cpu_us = (cpu1.sys - cpu0.sys) * 1e6 / n;
        std::sort(reply_ms.begin(), reply_ms.end());
        result.reply_median_ms = reply_ms[reply_ms.size() / 2];
        result.reply_p99_ms = reply_ms[std::min(reply_ms.size() - 1, reply_ms.size() * 99 / 100)];
    }
    return result;
}

}  // namespace fieldbridge::bench
