#pragma once
// fieldbridge-sim --r6 as a child process of an integration test: READY awaited
// (bounded), its control socket, killed and restarted at will.
#include <sys/types.h>

#include <cstdint>
#include <string>

namespace fbtest {

/// fieldbridge-sim --r6 127.0.0.1:PORT with a control socket, READY awaited (bounded).
class SimProcess {
public:
    explicit SimProcess(std::uint16_t port);
    ~SimProcess();
    SimProcess(const SimProcess&) = delete;
    SimProcess& operator=(const SimProcess&) = delete;

    /// Starts the simulator (again); throws when READY does not come within 20 s.
    void start();
    /// SIGTERM, then SIGKILL after 5 s; reaps the child.
    void kill();
    /// One control line, one reply line ("ok", "ok ...", "error: ...").
    [[nodiscard]] std::string control(const std::string& line);
    [[nodiscard]] std::uint16_t port() const noexcept { return port_; }

private:
    std::uint16_t port_;
    std::string dir_;
    pid_t pid_ = -1;
};

}  // namespace fbtest
