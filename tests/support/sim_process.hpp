#pragma once
/// @file sim_process.hpp
/// The real fieldbridge-sim binary as a child of a test or benchmark, the one way
/// they all start it: posix_spawn in a private temporary directory, READY awaited
/// (bounded), driven through its control socket (one line in, one line out), stopped
/// by PID and, after terminate(), started again on the same links and socket. The
/// destructor kills the process and removes the directory in every path, so a
/// failing REQUIRE never leaves a simulator behind.
///
/// The binary is named by the FIELDBRIDGE_SIM environment variable (the CTest entries
/// set it to $<TARGET_FILE:fieldbridge-sim>, tests/bench/run-benchmarks too). Its
/// stderr goes to `<dir>/sim.log`, which every error message quotes.
#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace fieldbridge::test {

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

    /// The temporary directory (bus links and the control socket live here).
    [[nodiscard]] const std::filesystem::path& dir() const noexcept { return dir_; }
    /// `<dir>/<name>`: the path of a bus link given as `{dir}/<name>`.
    [[nodiscard]] std::string path(std::string_view name) const;

    /// One control command; the reply line without its newline. Throws
    /// std::runtime_error when the socket refuses or does not answer within 5 s.
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
    /// After terminate(): starts the simulator again with the same arguments in the
    /// same directory (the same bus link paths, TCP endpoints and control socket),
    /// READY awaited as in the constructor. Throws std::logic_error while it runs.
    void start();
    [[nodiscard]] bool running() const noexcept { return pid_ >= 0; }
    /// The simulator's stderr so far (every start of it).
    [[nodiscard]] std::string log_text() const;

private:
    void spawn_and_await_ready();
    void kill_now() noexcept;
    [[nodiscard]] std::string socket_path() const;

    std::filesystem::path dir_;
    std::vector<std::string> argv_;  // the binary, the arguments with {dir} replaced, --control
    std::chrono::milliseconds ready_timeout_;
    pid_t pid_ = -1;
    int exit_status_ = -1;
};

}  // namespace fieldbridge::test
