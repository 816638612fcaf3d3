#include "sim_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "temp_dir.hpp"
#include "unique_fd.hpp"

extern char** environ;

namespace fieldbridge::test {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;
using Fd = test_support::UniqueFd;

constexpr auto control_timeout = std::chrono::seconds{5};

std::string errno_text(const std::string& what) { return what + ": " + std::strerror(errno); }

/// The binary FIELDBRIDGE_SIM names; throws with what to set when it names none.
std::string sim_binary() {
    const char* path = std::getenv("FIELDBRIDGE_SIM");
    if (path == nullptr || *path == '\0') {
        throw std::runtime_error(
            "FIELDBRIDGE_SIM is not set: it must name the fieldbridge-sim binary (ctest and "
            "tests/bench/run-benchmarks set it; by hand: FIELDBRIDGE_SIM=<build>/tests/sim/runtime/fieldbridge-sim)");
    }
    if (::access(path, X_OK) != 0) {
        throw std::runtime_error(errno_text(std::string("FIELDBRIDGE_SIM=") + path +
                                            " is not an executable fieldbridge-sim") +
                                 " (build the fieldbridge-sim target, or correct the path)");
    }
    return path;
}

std::string replace_dir(std::string arg, const std::string& dir) {
    for (auto at = arg.find("{dir}"); at != std::string::npos; at = arg.find("{dir}", at + dir.size())) {
        arg.replace(at, 5, dir);
    }
    return arg;
}

std::string command_line(const std::vector<std::string>& argv) {
    std::string text;
    for (const auto& arg : argv) text += (text.empty() ? "" : " ") + arg;
    return text;
}

/// Milliseconds left until @p deadline, at least 0, for poll().
int ms_left(Clock::time_point deadline) {
    const auto left = std::chrono::duration_cast<milliseconds>(deadline - Clock::now()).count();
    return left > 0 ? static_cast<int>(left) : 0;
}

}  // namespace

SimProcess::SimProcess(const std::vector<std::string>& args, std::chrono::milliseconds ready_timeout)
    : dir_(make_temp_dir("fb-sim")), ready_timeout_(ready_timeout) {
    try {
        argv_.push_back(sim_binary());
        for (const auto& arg : args) argv_.push_back(replace_dir(arg, dir_.string()));
        argv_.push_back("--control");
        argv_.push_back(socket_path());
        spawn_and_await_ready();
    } catch (...) {
        std::error_code ignored;
        std::filesystem::remove_all(dir_, ignored);
        throw;
    }
}

SimProcess::~SimProcess() {
    kill_now();
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
}

void SimProcess::start() {
    if (running()) throw std::logic_error("SimProcess::start: fieldbridge-sim still runs; terminate() it first");
    spawn_and_await_ready();
}

void SimProcess::spawn_and_await_ready() {
    try {
        std::vector<char*> argv;
        for (auto& arg : argv_) argv.push_back(arg.data());
        argv.push_back(nullptr);

        int pipe_fds[2];
        if (::pipe2(pipe_fds, O_CLOEXEC) != 0) {
            throw std::runtime_error(errno_text("pipe2 for fieldbridge-sim's stdout"));
        }
        Fd out_read(pipe_fds[0]);
        Fd out_write(pipe_fds[1]);
        const std::string log_path = (dir_ / "sim.log").string();

        // The log is appended to: after a restart it still holds the earlier runs.
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
        posix_spawn_file_actions_adddup2(&actions, out_write.get(), 1);
        posix_spawn_file_actions_addopen(&actions, 2, log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
        const int spawned = ::posix_spawn(&pid_, argv_[0].c_str(), &actions, nullptr, argv.data(), environ);
        posix_spawn_file_actions_destroy(&actions);
        if (spawned != 0) {
            pid_ = -1;
            throw std::runtime_error("cannot start " + argv_[0] + ": " + std::strerror(spawned));
        }
        out_write.reset();

        // READY on stdout once every pty, TCP listener and the control socket exist
        // (docs/simulator.md). The read end is closed afterwards: the simulator prints
        // nothing else there.
        const auto deadline = Clock::now() + ready_timeout_;
        std::string seen;
        while (seen.find("READY\n") == std::string::npos) {
            pollfd pfd{out_read.get(), POLLIN, 0};
            const int left = ms_left(deadline);
            if (left == 0 || ::poll(&pfd, 1, left) <= 0) {
                throw std::runtime_error("fieldbridge-sim did not print READY within " +
                                         std::to_string(ready_timeout_.count()) + " ms (a busy machine, or a bus "
                                         "or endpoint it cannot open?); command: " + command_line(argv_) +
                                         "\nits log (" + log_path + "):\n" + log_text());
            }
            char buffer[256];
            const ssize_t got = ::read(out_read.get(), buffer, sizeof buffer);
            if (got <= 0) {
                const int status = terminate(milliseconds{2000});
                throw std::runtime_error("fieldbridge-sim exited with status " + std::to_string(status) +
                                         " before READY; command: " + command_line(argv_) + "\nits log (" +
                                         log_path + "):\n" + log_text());
            }
            seen.append(buffer, static_cast<std::size_t>(got));
        }
    } catch (...) {
        kill_now();
        throw;
    }
}

std::string SimProcess::path(std::string_view name) const { return (dir_ / std::string(name)).string(); }

std::string SimProcess::socket_path() const { return (dir_ / "sim.sock").string(); }

std::string SimProcess::control(std::string_view line) const {
    const auto deadline = Clock::now() + control_timeout;
    const std::string where = "fieldbridge-sim's control socket " + socket_path();
    const std::string state = running() ? "" : " (the simulator is not running: terminate() stopped it)";
    Fd sock(::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0));
    if (sock.get() < 0) throw std::runtime_error(errno_text("socket(AF_UNIX) for " + where));
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    const std::string socket_file = socket_path();
    if (socket_file.size() >= sizeof address.sun_path) {
        throw std::runtime_error(where + ": the path is longer than a Unix socket allows (set TMPDIR shorter)");
    }
    std::memcpy(address.sun_path, socket_file.c_str(), socket_file.size() + 1);
    if (::connect(sock.get(), reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
        throw std::runtime_error(errno_text("cannot connect to " + where + state) + "; its log:\n" + log_text());
    }
    const std::string request = std::string(line) + "\n";
    if (::send(sock.get(), request.data(), request.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(request.size())) {
        throw std::runtime_error(errno_text("cannot send '" + std::string(line) + "' to " + where));
    }
    std::string reply;
    while (reply.empty() || reply.back() != '\n') {
        pollfd pfd{sock.get(), POLLIN, 0};
        const int left = ms_left(deadline);
        if (left == 0 || ::poll(&pfd, 1, left) <= 0) {
            throw std::runtime_error("no reply to '" + std::string(line) + "' on " + where + " within 5 s" + state +
                                     "; its log:\n" + log_text());
        }
        char buffer[4096];
        const ssize_t got = ::recv(sock.get(), buffer, sizeof buffer, 0);
        if (got <= 0) break;
        reply.append(buffer, static_cast<std::size_t>(got));
    }
    if (!reply.empty() && reply.back() == '\n') reply.pop_back();
    return reply;
}

void SimProcess::command(std::string_view line) const {
    const std::string reply = control(line);
    if (reply != "ok" && reply.rfind("ok ", 0) != 0) {
        throw std::runtime_error("fieldbridge-sim refused the control command '" + std::string(line) + "': " + reply +
                                 " (docs/simulator.md lists the commands)");
    }
}

nlohmann::json SimProcess::stats() const {
    const std::string reply = control("stats");
    if (reply.rfind("ok ", 0) != 0) throw std::runtime_error("fieldbridge-sim's 'stats' failed: " + reply);
    return nlohmann::json::parse(reply.substr(3));
}

std::uint64_t SimProcess::device_counter(std::string_view bus, unsigned address, std::string_view counter) const {
    const auto json = stats();
    return json.at("buses").at(std::string(bus)).at("devices").at(std::to_string(address)).at(std::string(counter))
        .get<std::uint64_t>();
}

std::uint64_t SimProcess::bus_counter(std::string_view bus, std::string_view counter) const {
    return stats().at("buses").at(std::string(bus)).at(std::string(counter)).get<std::uint64_t>();
}

int SimProcess::terminate(std::chrono::milliseconds timeout) {
    if (pid_ < 0) return exit_status_;
    ::kill(pid_, SIGTERM);
    const auto deadline = Clock::now() + timeout;
    while (Clock::now() < deadline) {
        int status = 0;
        const pid_t done = ::waitpid(pid_, &status, WNOHANG);
        if (done == pid_) {
            pid_ = -1;
            exit_status_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
            return exit_status_;
        }
        // A child process is not a loop's event: a short bounded poll is the simple way.
        std::this_thread::sleep_for(milliseconds{10});
    }
    kill_now();
    return -1;
}

void SimProcess::kill_now() noexcept {
    if (pid_ < 0) return;
    ::kill(pid_, SIGKILL);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
    exit_status_ = -1;
}

std::string SimProcess::log_text() const {
    std::ifstream in(dir_ / "sim.log");
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

}  // namespace fieldbridge::test
