#pragma once
/// @file raw_master.hpp
/// The floor of the line benchmarks: the smallest possible Modbus-RTU master, written
/// straight on the system calls (write the request, poll() for the reply, read it,
/// clock_nanosleep() the 3.5-character silence from the moment it was read, again;
/// with a spin lead, sleep to the lead before the silence's end and busy-wait the rest).
/// It has no event loop, scheduler, register image or error handling worth the name;
/// what it costs per transaction on this machine is what the kernel, the
/// pseudo-terminal and the simulator process cost, and what it achieves is what the
/// simulator and the machine's wake-up latency allow. fb_bench_line and
/// fb_bench_tcp_daemon report the gateway's figures next to it
/// (docs/performance.md).
///
/// It also checks the simulator's physics from the master's side of the pty, with
/// the master's own clock: no reply may be readable earlier than its request's wire
/// time + the device turnaround + the reply's wire time after the request's first
/// byte was written, and the silence the master keeps after each reply is measured.
#include <chrono>
#include <cstdint>
#include <string>

#include "load_shape.hpp"

namespace fieldbridge::bench {

struct RawMasterSetup {
    std::string path;  ///< the pty
    LoadShape shape{LoadShape::Kind::xeg};
    std::uint32_t baud = 115200;  ///< 8N1
    std::chrono::nanoseconds turnaround = std::chrono::milliseconds{1};  ///< the simulator's
    std::chrono::duration<double> duration{5.0};
    /// Zero: the silence is slept out with clock_nanosleep(). Otherwise the master
    /// sleeps until this long before the silence ends and spins to the instant, as the
    /// gateway does with `precise_timing` (the floor of that mode).
    std::chrono::nanoseconds spin_lead{0};
};

struct RawMasterResult {
    std::uint64_t transactions = 0;  ///< replies of the expected length
    std::uint64_t timeouts = 0;
    double seconds = 0.0;
    double user_cpu_us = 0.0;  ///< per transaction
    double sys_cpu_us = 0.0;   ///< per transaction
    /// From before the request's write to the reply's last byte read, over the
    /// transactions answered: what a client sees of the simulator's wire time.
    double reply_min_ms = 0.0;
    double reply_median_ms = 0.0;
    double reply_p99_ms = 0.0;
    /// The physical bound of a reply: request on the wire + turnaround + reply on the
    /// wire (no silence); replies read earlier than that after the write began.
    double reply_bound_ms = 0.0;
    std::uint64_t early_replies = 0;
    /// From the reply's last byte read to the next request's write: the silence the
    /// master kept (it sleeps t3.5; the rest is its wake-up latency).
    double silence_min_us = 0.0;
    double silence_median_us = 0.0;
    double silence_p99_us = 0.0;
    double spin_lead_us = 0.0;  ///< RawMasterSetup::spin_lead: 0 when the silence was slept
};

/// Runs the reads of @p setup.shape on @p setup.path until @p setup.duration has
/// passed. Throws std::runtime_error when the port cannot be opened or written.
[[nodiscard]] RawMasterResult run_raw_master(const RawMasterSetup& setup);

}  // namespace fieldbridge::bench
