#pragma once
/// @file sim_process.hpp
/// The real fieldbridge-sim binary for the engine's integration tests: started with
/// posix_spawn in a private temporary directory, READY awaited (bounded), driven
/// through its control socket (one line in, one line out), stopped by PID. The
/// destructor kills the process and removes the directory in every path, so a
/// failing REQUIRE never leaves a simulator behind.
///
/// The binary is named by the FIELDBRIDGE_SIM environment variable (CMake sets it to
/// $<TARGET_FILE:fieldbridge-sim>).
#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace fieldbridge::integration {

class SimProcess {
public:
    /// Starts the simulator with @p args plus `--control <dir>/sim.sock`; a `{dir}`
    /// in an argument is replaced by the temporary directory. Throws
    /// std::runtime_error (with the simulator's log) when it does not print READY
    /// within @p ready_timeout.
    explicit SimProcess(const std::vector<std::string>& args,
                        std::chrono::milliseconds ready_timeout = std::chrono::seconds{20});
    ~SimProcess();
    SimProcess(const SimProcess&) = delete;
    SimProcess& operator=(const SimProcess&) = delete;

    /// The temporary directory (bus links live here).
    [[nodiscard]] const std::filesystem::path& dir() const noexcept { return dir_; }
    /// `<dir>/<name>`: the path of a bus link given as `{dir}/<name>`.
    [[nodiscard]] std::string path(std::string_view name) const;

    /// One control command; the reply line without its newline. Throws
    /// std::runtime_error when the socket does not answer within 5 s.
    [[nodiscard]] std::string control(std::string_view line) const;
    /// control() that must answer `ok`/`ok ...`; throws with the reply otherwise.
    void command(std::string_view line) const;
    /// The `stats` JSON.
    [[nodiscard]] nlohmann::json stats() const;
    /// stats()["buses"][bus]["devices"][address][counter], as a number.
    [[nodiscard]] std::uint64_t device_counter(std::string_view bus, unsigned address,
                                               std::string_view counter) const;
    /// stats()["buses"][bus][counter], as a number.
    [[nodiscard]] std::uint64_t bus_counter(std::string_view bus, std::string_view counter) const;

    /// SIGTERM, then a bounded wait; the exit status (0 for a clean stop), or -1 when
    /// it had to be killed. Idempotent.
    int terminate(std::chrono::milliseconds timeout = std::chrono::seconds{10});
    /// The simulator's stderr so far.
    [[nodiscard]] std::string log_text() const;

private:
    void kill_now() noexcept;

    std::filesystem::path dir_;
    pid_t pid_ = -1;
    int exit_status_ = -1;
};

}  // namespace fieldbridge::integration
