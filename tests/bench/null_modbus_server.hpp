#pragma once
/// @file null_modbus_server.hpp
/// A Modbus TCP server that does nothing but answer: on its own thread, one epoll
/// set, every read (FC03 / FC04) answered at once with zeros, anything else with
/// exception 01. What a load generator measures against it is the generator's own
/// tail (and the loopback TCP path's), the reference for the daemon's figures.
#include <cstdint>
#include <thread>

namespace fieldbridge::bench {

class NullModbusServer {
public:
    /// Listens on a free loopback port and starts serving. Throws
    /// std::runtime_error when it cannot listen.
    NullModbusServer();
    /// Stops the thread and closes every connection.
    ~NullModbusServer();
    NullModbusServer(const NullModbusServer&) = delete;
    NullModbusServer& operator=(const NullModbusServer&) = delete;

    [[nodiscard]] std::uint16_t port() const noexcept { return port_; }

private:
    void serve();

    int listen_fd_ = -1;
    int stop_fd_ = -1;  ///< eventfd: written to stop
    std::uint16_t port_ = 0;
    std::thread thread_;
};

}  // namespace fieldbridge::bench
