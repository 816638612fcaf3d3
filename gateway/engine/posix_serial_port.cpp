#include "engine/posix_serial_port.hpp"

#include <fcntl.h>
#include <linux/serial.h>
#include <modbus/modbus.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

namespace fieldbridge::engine {

namespace {

std::string hint_for(int error) {
    switch (error) {
        case ENOENT:
        case ENODEV:
        case ENXIO:
            return "check that the adapter is plugged in and the path in the config is right";
        case EACCES:
        case EPERM:
            return "the service user needs to be in the 'dialout' group";
        case EBUSY:
            return "another program holds the port; stop it (only one master per line)";
        case EIO:
            return "the device went away (adapter unplugged?); the line reopens by itself when it returns";
        case ENOTTY:
        case EINVAL:
            return "the path is not a serial port, or the driver does not support this setting";
        default:
            return "see the system log for the driver's message";
    }
}

}  // namespace

void PosixSerialPort::ContextDeleter::operator()(_modbus* ctx) const noexcept {
    modbus_close(ctx);
    modbus_free(ctx);
}

PosixSerialPort::PosixSerialPort(SerialSettings settings, SerialIoctls ioctls)
    : settings_(std::move(settings)), ioctls_(std::move(ioctls)) {}

PosixSerialPort::~PosixSerialPort() { close(); }

void PosixSerialPort::fail(const char* what, int error) {
    close();
    throw SerialPortError(std::string(what) + ": " + std::strerror(error), "serial port " + settings_.path,
                          hint_for(error));
}

void PosixSerialPort::open() {
    if (is_open()) return;
    modbus_t* raw = modbus_new_rtu(settings_.path.c_str(), static_cast<int>(settings_.baud),
                                   core::parity_letter(settings_.parity), static_cast<int>(settings_.data_bits),
                                   static_cast<int>(settings_.stop_bits));
    if (raw == nullptr) fail("cannot create the port context (invalid settings)", errno);
    ctx_.reset(raw);
    // modbus_connect opens non-blocking (O_NDELAY) and applies termios raw mode with
    // the configured baud, parity, data and stop bits.
    if (modbus_connect(raw) == -1) fail("cannot open", errno);
    fd_ = modbus_get_socket(raw);
    if (fd_ < 0) fail("no file descriptor after open", EBADF);
    const int flags = ::fcntl(fd_, F_GETFL);
    if (flags == -1 || ::fcntl(fd_, F_SETFL, flags | O_NONBLOCK) == -1) {
        fail("cannot make the port non-blocking", errno);
    }
    // libmodbus leaves VMIN = 0, VTIME = 0, where a read with no data returns 0 even
    // on a non-blocking descriptor (n_tty), indistinguishable from a hang-up. With
    // VMIN = 1 an idle read fails with EAGAIN and 0 means hang-up, as read_some expects.
    termios tio{};
    if (::tcgetattr(fd_, &tio) == -1) fail("cannot read the terminal settings", errno);
    tio.c_cc[VMIN] = 1;
    tio.c_cc[VTIME] = 0;
    if (::tcsetattr(fd_, TCSANOW, &tio) == -1) fail("cannot set the terminal read mode", errno);
    if (settings_.rs485) apply_rs485();
    // Not a reason to refuse the port: the line works, only slower on some adapters.
    low_latency_ = request_low_latency(fd_, ioctls_);
    discard_input();
}

void PosixSerialPort::apply_rs485() {
    // libmodbus turns the kernel RS-485 mode on (TIOCSRS485 with SER_RS485_ENABLED);
    // the RTS polarity and delays are then set on the same kernel structure, so the
    // driver, not user space, switches the transceiver around each transmission.
    if (modbus_rtu_set_serial_mode(ctx_.get(), MODBUS_RTU_RS485) == -1) {
        fail("cannot enable kernel RS-485 mode (TIOCSRS485)", errno);
    }
    serial_rs485 rs485{};
    if (::ioctl(fd_, TIOCGRS485, &rs485) == -1) fail("cannot read the RS-485 settings", errno);
    rs485.flags |= SER_RS485_ENABLED;
    rs485.flags = settings_.rts_on_send ? (rs485.flags | SER_RS485_RTS_ON_SEND)
                                        : (rs485.flags & ~static_cast<__u32>(SER_RS485_RTS_ON_SEND));
    rs485.flags = settings_.rts_after_send
                      ? (rs485.flags | SER_RS485_RTS_AFTER_SEND)
                      : (rs485.flags & ~static_cast<__u32>(SER_RS485_RTS_AFTER_SEND));
    rs485.delay_rts_before_send = settings_.delay_rts_before_send_ms;
    rs485.delay_rts_after_send = settings_.delay_rts_after_send_ms;
    if (::ioctl(fd_, TIOCSRS485, &rs485) == -1) fail("cannot set the RS-485 RTS settings", errno);
}

void PosixSerialPort::close() noexcept {
    ctx_.reset();
    fd_ = -1;
}

bool PosixSerialPort::is_open() const noexcept { return fd_ >= 0; }

int PosixSerialPort::native_handle() const noexcept { return fd_; }

std::size_t PosixSerialPort::write_some(protocol::ByteView bytes) {
    if (!is_open()) throw SerialPortError("serial port " + settings_.path + ": write while closed");
    const ssize_t n = ::write(fd_, bytes.data(), bytes.size());
    if (n >= 0) return static_cast<std::size_t>(n);
    if (errno == EAGAIN || errno == EINTR) return 0;
    fail("write failed", errno);
}

std::size_t PosixSerialPort::read_some(std::span<std::uint8_t> buffer) {
    if (!is_open()) throw SerialPortError("serial port " + settings_.path + ": read while closed");
    const ssize_t n = ::read(fd_, buffer.data(), buffer.size());
    if (n > 0) return static_cast<std::size_t>(n);
    // A non-blocking tty read returns -1/EAGAIN when idle; 0 means hang-up.
    if (n == 0) fail("hang-up (the other end closed)", EIO);
    if (errno == EAGAIN || errno == EINTR) return 0;
    fail("read failed", errno);
}

void PosixSerialPort::discard_input() noexcept {
    if (is_open()) ::tcflush(fd_, TCIFLUSH);
}

}  // namespace fieldbridge::engine
