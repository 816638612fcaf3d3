#pragma once
// fieldbridge-sim started by a test (READY awaited, bounded) and its control socket.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <doctest/doctest.h>

extern char** environ;

namespace fbt {

using namespace std::chrono_literals;

/// fieldbridge-sim with @p args and a control socket at DIR/ctl; waits for READY.
class Sim {
public:
    Sim(const std::string& dir, std::vector<std::string> extra) : dir_(dir) {
        int out[2];
        REQUIRE(::pipe(out) == 0);
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
        posix_spawn_file_actions_addclose(&actions, out[0]);
        std::vector<std::string> args{FB_SIM, "--control", dir + "/ctl", "--log-level", "warn"};
        args.insert(args.end(), extra.begin(), extra.end());
        std::vector<char*> argv;
        for (auto& a : args) argv.push_back(a.data());
        argv.push_back(nullptr);
        REQUIRE(::posix_spawn(&pid_, FB_SIM, &actions, nullptr, argv.data(), environ) == 0);
        posix_spawn_file_actions_destroy(&actions);
        ::close(out[1]);
        std::string got;
        const auto until = std::chrono::steady_clock::now() + 20s;
        while (got.find("READY\n") == std::string::npos && std::chrono::steady_clock::now() < until) {
            pollfd p{out[0], POLLIN, 0};
            if (::poll(&p, 1, 100) > 0) {
                char buffer[256];
                const auto n = ::read(out[0], buffer, sizeof buffer);
                if (n <= 0) break;
                got.append(buffer, static_cast<std::size_t>(n));
            }
        }
        ::close(out[0]);
        REQUIRE_MESSAGE(got.find("READY\n") != std::string::npos, "fieldbridge-sim did not print READY in 20 s");
    }
    ~Sim() {
        ::kill(pid_, SIGTERM);
        int status = 0;
        const auto until = std::chrono::steady_clock::now() + 10s;
        while (::waitpid(pid_, &status, WNOHANG) == 0) {
            if (std::chrono::steady_clock::now() > until) {
                ::kill(pid_, SIGKILL);
                ::waitpid(pid_, &status, 0);
                break;
            }
            ::usleep(10'000);
        }
    }
    /// One control command; returns the reply line.
    std::string control(const std::string& command) {
        const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
        sockaddr_un a{};
        a.sun_family = AF_UNIX;
        const std::string path = dir_ + "/ctl";
        std::snprintf(a.sun_path, sizeof a.sun_path, "%s", path.c_str());
        REQUIRE(::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0);
        const std::string line = command + "\n";
        REQUIRE(::write(fd, line.data(), line.size()) == static_cast<ssize_t>(line.size()));
        std::string reply;
        const auto until = std::chrono::steady_clock::now() + 5s;
        while (reply.find('\n') == std::string::npos && std::chrono::steady_clock::now() < until) {
            pollfd p{fd, POLLIN, 0};
            if (::poll(&p, 1, 100) > 0) {
                char buffer[256];
                const auto n = ::read(fd, buffer, sizeof buffer);
                if (n <= 0) break;
                reply.append(buffer, static_cast<std::size_t>(n));
            }
        }
        ::close(fd);
        return reply;
    }

private:
    std::string dir_;
    pid_t pid_ = -1;
};

}  // namespace fbt
