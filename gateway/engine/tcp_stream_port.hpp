#pragma once
/// @file tcp_stream_port.hpp
/// A line reached through a serial device server in transparent mode (Moxa NPort
/// "TCP Server", USR-TCP232 "TCP Server", ...): one TCP connection that carries the
/// raw RTU or WTEC ASCII bytes of the far side's RS-485 line. It is a SerialPort, so
/// everything above it (line core, scheduler, master, profiles) is the same as on a
/// tty; only the open differs: a name resolution and a connect with a timeout, then
/// TCP_NODELAY (a request leaves at once, not after Nagle's delay), keepalive and a
/// user timeout (a device server that vanished is noticed in seconds, idle or not).
/// None of the serial set-up (termios, RS-485 ioctl, low latency) is made.
///
/// The daemon's worker opens it without blocking its loop (ConnectWait::begin: open()
/// starts the connect, the worker waits for the fd to turn writable, then calls
/// finish_open()); the scan tool, which has nothing else to do, waits in open()
/// (ConnectWait::block). A host name is resolved at each open; a name that resolves
/// to several addresses is tried one address per attempt, in turn.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "engine/serial_port.hpp"

namespace fieldbridge::engine {

enum class ConnectWait : std::uint8_t {
    begin,  ///< open() starts the connect; opening() until finish_open()
    block,  ///< open() returns connected or throws (after at most the connect timeout)
};

class TcpStreamPort final : public SerialPort {
public:
    /// Throws core::InvalidArgument when @p settings has no tcp endpoint.
    explicit TcpStreamPort(SerialSettings settings, ConnectWait wait = ConnectWait::begin);
    ~TcpStreamPort() override;

    void open() override;
    void close() noexcept override;
    [[nodiscard]] bool is_open() const noexcept override { return fd_ >= 0; }
    [[nodiscard]] int native_handle() const noexcept override { return fd_; }
    [[nodiscard]] std::size_t write_some(protocol::ByteView bytes) override;
    [[nodiscard]] std::size_t read_some(std::span<std::uint8_t> buffer) override;
    void discard_input() noexcept override;
    [[nodiscard]] const SerialSettings& settings() const noexcept override { return settings_; }
    [[nodiscard]] std::string open_detail() const override;
    [[nodiscard]] bool opening() const noexcept override { return opening_; }
    void finish_open() override;
    [[nodiscard]] std::chrono::milliseconds open_timeout() const noexcept override {
        return settings_.tcp->connect_timeout;
    }

private:
    /// The addresses the host resolves to now. Throws SerialPortError.
    void resolve();
    void set_options();
    [[nodiscard]] std::string peer() const;
    [[noreturn]] void fail(const std::string& what, int error, const char* advice);

    SerialSettings settings_;
    ConnectWait wait_;
    std::vector<std::vector<std::uint8_t>> addresses_;  ///< sockaddr bytes of the last resolution
    std::size_t next_address_ = 0;
    std::string connected_to_;  ///< the address text of the current connection
    int fd_ = -1;
    bool opening_ = false;
};

}  // namespace fieldbridge::engine
