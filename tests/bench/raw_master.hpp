#pragma once
/// @file raw_master.hpp
/// The floor of the line benchmark: the smallest possible Modbus-RTU master, written
/// straight on the system calls (write the request, poll() for the reply, read it,
/// clock_nanosleep() the 3.5-character silence from the moment it was read, again).
/// It has no event loop, scheduler, register image or error handling worth the name;
/// what it costs per transaction on this machine is what the kernel, the
/// pseudo-terminal and the simulator process cost, and what it achieves is what the
/// simulator and the machine's wake-up latency allow. fb_bench_line reports the
/// engine's figures next to it (docs/performance.md).
#include <chrono>
#include <cstdint>
#include <string>

namespace fieldbridge::bench {

struct RawMasterResult {
    std::uint64_t transactions = 0;  ///< replies of the expected length
    std::uint64_t timeouts = 0;
    double seconds = 0.0;
    double user_cpu_us = 0.0;  ///< per transaction
    double sys_cpu_us = 0.0;   ///< per transaction
    /// From before the request's write to the reply's last byte read, over the
    /// transactions answered: what a client sees of the simulator's wire time.
    double reply_median_ms = 0.0;
    double reply_p99_ms = 0.0;
};

/// Runs FC04 @p reg x2 to @p address on the pty @p path for @p duration at 115200 8N1.
/// Throws std::runtime_error when the port cannot be opened or written.
[[nodiscard]] RawMasterResult run_raw_master(const std::string& path, std::uint8_t address, std::uint16_t reg,
                                             std::chrono::duration<double> duration);

}  // namespace fieldbridge::bench
