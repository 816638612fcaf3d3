#pragma once
/// @file child_process.hpp
/// Processes beside the daemon in a benchmark: a child started with its stdout to a
/// file and stopped by PID (SIGTERM, then SIGKILL after a bounded wait; the destructor
/// stops it in every path), the CPU time of any process, and the PID of a child that
/// another helper started (the broker of broker_support).
#include <sys/types.h>

#include <filesystem>
#include <string>
#include <vector>

namespace fieldbridge::bench {

class ChildProcess {
public:
    /// Runs @p args (args[0] looked up in PATH) with its stdout to @p out. Throws
    /// std::runtime_error naming the program when it cannot be started.
    ChildProcess(const std::vector<std::string>& args, const std::filesystem::path& out);
    ~ChildProcess() { stop(); }
    ChildProcess(const ChildProcess&) = delete;
    ChildProcess& operator=(const ChildProcess&) = delete;

    [[nodiscard]] pid_t pid() const noexcept { return pid_; }
    /// SIGTERM, up to 3 s, then SIGKILL. Idempotent.
    void stop();

private:
    pid_t pid_ = -1;
};

/// utime + stime of process @p pid from /proc/<pid>/stat, in seconds (clock ticks);
/// 0 when unreadable.
[[nodiscard]] double process_cpu_seconds(pid_t pid);

/// The PID of this process's child whose command name is @p comm ("mosquitto"), or -1.
[[nodiscard]] pid_t child_named(const std::string& comm);

}  // namespace fieldbridge::bench
