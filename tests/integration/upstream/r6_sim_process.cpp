#include "r6_sim_process.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <thread>
#include <vector>

#include "temp_dir.hpp"

extern char** environ;

namespace fbtest {
namespace {

using Clock = std::chrono::steady_clock;

/// Reads one line from @p fd before @p deadline; false on timeout or EOF.
bool read_line(int fd, std::string& line, Clock::time_point deadline) {
    line.clear();
    for (;;) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
        if (left <= 0) return false;
        pollfd p{fd, POLLIN, 0};
        if (::poll(&p, 1, static_cast<int>(left)) <= 0) continue;
        char c = 0;
        const ssize_t n = ::read(fd, &c, 1);
        if (n <= 0) return false;
        if (c == '\n') return true;
        line.push_back(c);
    }
}

}  // namespace

// ---- SimProcess ---------------------------------------------------------------

SimProcess::SimProcess(std::uint16_t port) : port_(port) {
    dir_ = fieldbridge::test::make_temp_dir("fb-upstream").string();
    start();
}

SimProcess::~SimProcess() {
    kill();
    ::unlink((dir_ + "/sim.sock").c_str());
    ::rmdir(dir_.c_str());
}

void SimProcess::start() {
    if (pid_ > 0) return;
    int out[2];
    if (::pipe(out) != 0) throw std::runtime_error("pipe failed");
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
    posix_spawn_file_actions_addclose(&actions, out[0]);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, (dir_ + "/sim.log").c_str(),
                                     O_WRONLY | O_CREAT | O_APPEND, 0644);
    const std::string endpoint = fmt::format("127.0.0.1:{}", port_);
    const std::string control = dir_ + "/sim.sock";
    std::vector<std::string> args{FB_SIM_BINARY, "--r6", endpoint, "--control", control};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    const int rc = ::posix_spawn(&pid_, FB_SIM_BINARY, &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(out[1]);
    if (rc != 0) {
        ::close(out[0]);
        pid_ = -1;
        throw std::runtime_error(fmt::format("cannot start {}: {}", FB_SIM_BINARY, std::strerror(rc)));
    }
    // Sanitizer builds start slowly on a busy machine.
    const auto deadline = Clock::now() + std::chrono::seconds{20};
    std::string line;
    bool ready = false;
    while (read_line(out[0], line, deadline)) {
        if (line == "READY") {
            ready = true;
            break;
        }
    }
    ::close(out[0]);  // the simulator prints nothing else on stdout we need
    if (!ready) {
        kill();
        throw std::runtime_error(fmt::format("fieldbridge-sim did not print READY within 20 s (log: {}/sim.log)", dir_));
    }
}

void SimProcess::kill() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGTERM);
    const auto deadline = Clock::now() + std::chrono::seconds{5};
    int status = 0;
    while (::waitpid(pid_, &status, WNOHANG) == 0) {
        if (Clock::now() >= deadline) {
            ::kill(pid_, SIGKILL);
            ::waitpid(pid_, &status, 0);
            break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds{5});  // test thread, not a loop
    }
    pid_ = -1;
}

std::string SimProcess::control(const std::string& line) {
    const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
    if (fd < 0) throw std::runtime_error("socket failed");
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    const std::string path = dir_ + "/sim.sock";
    std::snprintf(addr.sun_path, sizeof addr.sun_path, "%s", path.c_str());
    if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
        ::close(fd);
        throw std::runtime_error("cannot connect to the simulator's control socket " + path);
    }
    const std::string request = line + "\n";
    if (::write(fd, request.data(), request.size()) != static_cast<ssize_t>(request.size())) {
        ::close(fd);
        throw std::runtime_error("control write failed");
    }
    std::string reply;
    const bool ok = read_line(fd, reply, Clock::now() + std::chrono::seconds{5});
    ::close(fd);
    if (!ok) throw std::runtime_error("no control reply to '" + line + "' within 5 s");
    return reply;
}

}  // namespace fbtest
