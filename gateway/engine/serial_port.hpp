#pragma once
/// @file serial_port.hpp
/// The seam around a line's byte stream: a serial port (PosixSerialPort) or a TCP
/// connection to a serial device server in transparent mode (TcpStreamPort). A line
/// worker owns exactly one SerialPort; tests inject a fake. Reads and writes are
/// non-blocking: the worker waits for readiness on native_handle() in its event loop.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>

#include "core/error.hpp"
#include "engine/serial_low_latency.hpp"
#include "protocol/bytes.hpp"

#include "core/parity.hpp"

namespace fieldbridge::engine {

/// The port could not be opened or vanished (USB adapter unplugged, pty closed).
/// what() says which port, what failed and what to check.
class SerialPortError : public core::Error {
public:
    using core::Error::Error;
};

/// A line behind a serial device server (`tcp://host:port`).
struct StreamEndpoint {
    std::string host;  ///< host name, IPv4, or IPv6 without brackets
    std::uint16_t port = 0;
    std::chrono::milliseconds connect_timeout{2000};
};

struct SerialSettings {
    std::string path;  ///< the device path, or the tcp://host:port of a device server
    /// Set: the line is a TCP stream to a device server; the baud, parity and bits
    /// describe the far side's line (wire time) and the rs485 fields do not apply.
    std::optional<StreamEndpoint> tcp;
    unsigned baud = 115200;
    core::Parity parity = core::Parity::none;
    unsigned data_bits = 8;
    unsigned stop_bits = 1;
    /// Kernel RS-485 mode (TIOCSRS485): the driver switches the transceiver.
    bool rs485 = false;
    bool rts_on_send = true;
    bool rts_after_send = false;
    unsigned delay_rts_before_send_ms = 0;
    unsigned delay_rts_after_send_ms = 0;
};

class SerialPort {
public:
    SerialPort() = default;
    virtual ~SerialPort() = default;
    SerialPort(const SerialPort&) = delete;
    SerialPort& operator=(const SerialPort&) = delete;

    /// Opens and configures the port. Throws SerialPortError.
    virtual void open() = 0;
    virtual void close() noexcept = 0;
    [[nodiscard]] virtual bool is_open() const noexcept = 0;
    /// File descriptor to wait on for readiness; -1 when closed.
    [[nodiscard]] virtual int native_handle() const noexcept = 0;
    /// Writes what the driver accepts now; returns the count (0 when it would block).
    /// Throws SerialPortError when the port is gone.
    [[nodiscard]] virtual std::size_t write_some(protocol::ByteView bytes) = 0;
    /// Reads what is available now; returns the count (0 when nothing is there).
    /// Throws SerialPortError when the port is gone.
    [[nodiscard]] virtual std::size_t read_some(std::span<std::uint8_t> buffer) = 0;
    /// Drops whatever is in the driver's input buffer (resynchronisation).
    virtual void discard_input() noexcept = 0;
    [[nodiscard]] virtual const SerialSettings& settings() const noexcept = 0;
    /// What the driver said to the low-latency request of the last open() (for the log).
    [[nodiscard]] virtual LowLatency low_latency() const noexcept { return {}; }
    /// What the last open() set up, for the log (a serial port: the low-latency answer).
    [[nodiscard]] virtual std::string open_detail() const { return to_string(low_latency()); }

    /// True when open() only began (a TCP connect in progress, the fd open): the fd
    /// turns writable when it completes, then the caller calls finish_open().
    [[nodiscard]] virtual bool opening() const noexcept { return false; }
    /// Completes the open that open() began. Throws SerialPortError (refused, ...);
    /// the port is closed then.
    virtual void finish_open() {}
    /// How long an open that only began may take before the caller gives up.
    [[nodiscard]] virtual std::chrono::milliseconds open_timeout() const noexcept { return {}; }
};

}  // namespace fieldbridge::engine
