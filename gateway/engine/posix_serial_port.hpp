#pragma once
/// @file posix_serial_port.hpp
/// A real serial port (or pseudo-terminal). libmodbus sets it up — termios for
/// baud, parity, data and stop bits, and the kernel RS-485 mode — and hands us the
/// file descriptor; every byte after that is read and written here, because the
/// line timing (silence, turnaround, echo, framing) is ours (spec §3 rule 11).

#include <memory>

#include "engine/serial_port.hpp"

struct _modbus;  // libmodbus' context type (modbus_t)

namespace fieldbridge::engine {

class PosixSerialPort final : public SerialPort {
public:
    /// @p ioctls: the driver calls of the low-latency request (a seam for tests).
    explicit PosixSerialPort(SerialSettings settings, SerialIoctls ioctls = SerialIoctls::system());
    ~PosixSerialPort() override;

    void open() override;
    void close() noexcept override;
    [[nodiscard]] bool is_open() const noexcept override;
    [[nodiscard]] int native_handle() const noexcept override;
    [[nodiscard]] std::size_t write_some(protocol::ByteView bytes) override;
    [[nodiscard]] std::size_t read_some(std::span<std::uint8_t> buffer) override;
    void discard_input() noexcept override;
    [[nodiscard]] const SerialSettings& settings() const noexcept override { return settings_; }
    [[nodiscard]] LowLatency low_latency() const noexcept override { return low_latency_; }

private:
    void apply_rs485();
    [[noreturn]] void fail(const char* what, int error);

    SerialSettings settings_;
    SerialIoctls ioctls_;
    LowLatency low_latency_;
    struct ContextDeleter {
        void operator()(_modbus* ctx) const noexcept;
    };
    std::unique_ptr<_modbus, ContextDeleter> ctx_;
    int fd_ = -1;
};

}  // namespace fieldbridge::engine
