#pragma once
/// @file line_worker_port.hpp
/// The line worker's handle on its serial port: the SerialPort (which owns the file
/// descriptor) plus an asio descriptor on that fd used for readiness only. asio never
/// owns the fd: the descriptor is assigned at each open and released before the port
/// closes the fd, so asio neither closes it nor keeps a stale epoll registration
/// when the next open reuses the number.

#include <asio/io_context.hpp>
#include <asio/posix/stream_descriptor.hpp>
#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>

#include "engine/serial_port.hpp"
#include "protocol/bytes.hpp"

namespace fieldbridge::engine {

class LinePort {
public:
    LinePort(asio::io_context& io, std::unique_ptr<SerialPort> port);
    ~LinePort();
    LinePort(const LinePort&) = delete;
    LinePort& operator=(const LinePort&) = delete;

    /// Opens the port and registers its fd for readiness. Throws SerialPortError
    /// (the port is closed again then).
    void open();
    /// Aborts pending waits (their handlers get operation_aborted), releases the fd
    /// from asio and closes the port. Safe when closed.
    void close() noexcept;
    [[nodiscard]] bool is_open() const noexcept;
    [[nodiscard]] const SerialSettings& settings() const noexcept { return port_->settings(); }
    [[nodiscard]] std::string open_detail() const { return port_->open_detail(); }
    /// The open only began (a TCP connect): wait_writable(), then finish_open().
    [[nodiscard]] bool opening() const noexcept { return port_->opening(); }
    /// Throws SerialPortError (the port is closed again then).
    void finish_open();
    [[nodiscard]] std::chrono::milliseconds open_timeout() const noexcept { return port_->open_timeout(); }

    /// What the driver accepts now (0: it would block). Throws SerialPortError.
    [[nodiscard]] std::size_t write_some(protocol::ByteView bytes);
    /// What is readable now, into a buffer reused across calls (valid until the next
    /// read); empty when nothing is there. Throws SerialPortError (EIO, hang-up).
    [[nodiscard]] protocol::ByteView read_some();
    /// True when the last read filled the buffer (more may be waiting).
    [[nodiscard]] bool buffer_filled() const noexcept { return last_read_ == buffer_.size(); }

    /// Calls @p handler(asio::error_code) once the fd is readable (or hung up).
    template <typename Handler>
    void wait_readable(Handler&& handler) {
        descriptor_.async_wait(asio::posix::descriptor_base::wait_read, std::forward<Handler>(handler));
    }
    /// Calls @p handler(asio::error_code) once the fd accepts more bytes.
    template <typename Handler>
    void wait_writable(Handler&& handler) {
        descriptor_.async_wait(asio::posix::descriptor_base::wait_write, std::forward<Handler>(handler));
    }

private:
    std::unique_ptr<SerialPort> port_;
    asio::posix::stream_descriptor descriptor_;
    // One RTU ADU is at most 256 bytes; a read rarely brings more than one.
    std::array<std::uint8_t, 256> buffer_{};
    std::size_t last_read_ = 0;
};

}  // namespace fieldbridge::engine
