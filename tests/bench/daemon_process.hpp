#pragma once
/// @file daemon_process.hpp
/// The real `fieldbridge` daemon for the benchmarks: started with posix_spawn on a
/// configuration file, its log (stdout and stderr) written to a file, "ready" awaited
/// (bounded), stopped by PID (SIGTERM, then SIGKILL after a bounded wait). The
/// destructor stops it in every path.
#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <string>

namespace fieldbridge::bench {

class DaemonProcess {
public:
    /// Runs `@p binary --config @p config`, logging to @p log. Throws
    /// std::runtime_error (with the log) when "ready" does not appear within
    /// @p ready_timeout or the process exits first.
    DaemonProcess(const std::filesystem::path& binary, const std::filesystem::path& config,
                  std::filesystem::path log, std::chrono::milliseconds ready_timeout = std::chrono::seconds{20});
    ~DaemonProcess();
    DaemonProcess(const DaemonProcess&) = delete;
    DaemonProcess& operator=(const DaemonProcess&) = delete;

    [[nodiscard]] pid_t pid() const noexcept { return pid_; }
    /// User + system CPU time the daemon used so far (its process CPU-time clock, ns).
    [[nodiscard]] double cpu_seconds() const;
    /// Resident set size in KiB (VmRSS of /proc/<pid>/status); 0 when unreadable.
    [[nodiscard]] long rss_kib() const { return proc_kib("status", "VmRSS:"); }
    /// The largest resident set size so far (VmHWM), in KiB; 0 when unreadable.
    [[nodiscard]] long peak_rss_kib() const { return proc_kib("status", "VmHWM:"); }
    /// A field of /proc/<pid>/smaps_rollup ("Pss:", "Pss_Anon:", "Private_Dirty:"...)
    /// in KiB; 0 when unreadable.
    [[nodiscard]] long memory_kib(const std::string& field) const { return proc_kib("smaps_rollup", field); }
    /// A field of /proc/<pid>/status ("RssAnon:", "RssFile:"...) in KiB, or a count
    /// ("Threads:"); 0 when unreadable.
    [[nodiscard]] long status_field(const std::string& field) const { return proc_kib("status", field); }
    /// SIGTERM, bounded wait, SIGKILL; the exit status or -1 when killed. Idempotent.
    int terminate(std::chrono::milliseconds timeout = std::chrono::seconds{10});
    [[nodiscard]] std::string log_text() const;
    /// Waits (bounded) until the log holds @p text; false when it did not in time.
    [[nodiscard]] bool wait_for_log(const std::string& text, std::chrono::milliseconds timeout) const;
    /// Prints the log's warnings and errors so far (the first eight, and how many in
    /// all), each line prefixed with @p when: a figure that looks wrong usually has its
    /// reason there (timeouts, a device gone offline).
    void print_warnings(const std::string& when) const;

private:
    /// A "Name:   123 kB" field of /proc/<pid>/@p file, in KiB; 0 when unreadable.
    [[nodiscard]] long proc_kib(const std::string& file, const std::string& field) const;

    std::filesystem::path log_;
    pid_t pid_ = -1;
    int exit_status_ = -1;
};

}  // namespace fieldbridge::bench
