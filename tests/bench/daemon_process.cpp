#include "daemon_process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <time.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

extern char** environ;

namespace fieldbridge::bench {

namespace {
using Clock = std::chrono::steady_clock;
}

DaemonProcess::DaemonProcess(const std::filesystem::path& binary, const std::filesystem::path& config,
                             std::filesystem::path log, std::chrono::milliseconds ready_timeout)
    : log_(std::move(log)) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
    std::vector<std::string> args{binary.string(), "--config", config.string()};
    std::vector<char*> argv;
    for (auto& arg : args) argv.push_back(arg.data());
    argv.push_back(nullptr);
    const int rc = posix_spawn(&pid_, binary.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) {
        pid_ = -1;
        throw std::runtime_error("cannot start " + binary.string() + ": error " + std::to_string(rc) +
                                 "; build it first (tests/bench/run-benchmarks does)");
    }
    const auto deadline = Clock::now() + ready_timeout;
    while (log_text().find("ready") == std::string::npos) {
        int status = 0;
        if (waitpid(pid_, &status, WNOHANG) == pid_) {
            pid_ = -1;
            throw std::runtime_error("fieldbridge exited during start-up; its log:\n" + log_text());
        }
        if (Clock::now() >= deadline) {
            terminate();
            throw std::runtime_error("fieldbridge did not log \"ready\" in time; its log:\n" + log_text());
        }
        std::this_thread::sleep_for(std::chrono::milliseconds{20});
    }
}

DaemonProcess::~DaemonProcess() { terminate(); }

double DaemonProcess::cpu_seconds() const {
    // The process CPU-time clock of another process: nanosecond resolution, where
    // /proc/<pid>/stat counts 10 ms ticks (too coarse for a few thousand transactions).
    clockid_t clock{};
    if (clock_getcpuclockid(pid_, &clock) != 0) return 0.0;
    timespec used{};
    if (clock_gettime(clock, &used) != 0) return 0.0;
    return static_cast<double>(used.tv_sec) + static_cast<double>(used.tv_nsec) / 1e9;
}

long DaemonProcess::proc_kib(const std::string& file, const std::string& field) const {
    std::ifstream in("/proc/" + std::to_string(pid_) + "/" + file);
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind(field, 0) == 0) return std::stol(line.substr(field.size()));
    }
    return 0;
}

int DaemonProcess::terminate(std::chrono::milliseconds timeout) {
    if (pid_ <= 0) return exit_status_;
    kill(pid_, SIGTERM);
    const auto deadline = Clock::now() + timeout;
    int status = 0;
    while (waitpid(pid_, &status, WNOHANG) == 0) {
        if (Clock::now() >= deadline) {
            kill(pid_, SIGKILL);
            waitpid(pid_, &status, 0);
            pid_ = -1;
            exit_status_ = -1;
            return exit_status_;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds{10});
    }
    pid_ = -1;
    exit_status_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return exit_status_;
}

std::string DaemonProcess::log_text() const {
    std::ifstream in(log_);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

bool DaemonProcess::wait_for_log(const std::string& text, std::chrono::milliseconds timeout) const {
    const auto deadline = Clock::now() + timeout;
    while (log_text().find(text) == std::string::npos) {
        if (Clock::now() >= deadline) return false;
        std::this_thread::sleep_for(std::chrono::milliseconds{20});
    }
    return true;
}

void DaemonProcess::print_warnings(const std::string& when) const {
    std::istringstream lines(log_text());
    std::string line;
    int shown = 0;
    int total = 0;
    while (std::getline(lines, line)) {
        if (line.find("[warning]") == std::string::npos && line.find("[error]") == std::string::npos) continue;
        ++total;
        if (shown < 8) {
            std::printf("daemon log %s: %s\n", when.c_str(), line.c_str());
            ++shown;
        }
    }
    if (total > shown) std::printf("daemon log %s: ... %d warnings/errors in all\n", when.c_str(), total);
}

}  // namespace fieldbridge::bench
