#pragma once
/// @file serial_low_latency.hpp
/// Asks a serial driver for low latency (`ASYNC_LOW_LATENCY` through
/// TIOCGSERIAL/TIOCSSERIAL). USB adapters otherwise hold received bytes back: an FTDI
/// chip waits for its latency timer (16 ms by default) before it hands a short reply
/// to the host, longer than a whole transaction at 115200 bit/s. Drivers that know
/// the flag (ftdi_sio, 8250) shorten it; pseudo-terminals and many others do not
/// support the request (ENOTTY), which is not an error. The ioctls go through a seam
/// so that tests can play a driver that accepts, refuses or ignores the flag.

#include <functional>
#include <string>

struct serial_struct;

namespace fieldbridge::engine {

/// The two ioctls on an open descriptor; each returns 0 or the errno of the failure.
struct SerialIoctls {
    std::function<int(int fd, serial_struct& out)> get;
    std::function<int(int fd, const serial_struct& in)> set;

    /// The real ::ioctl calls.
    [[nodiscard]] static SerialIoctls system();
};

struct LowLatency {
    enum class Outcome {
        not_requested,  ///< the port is not open (or not a POSIX port)
        enabled,        ///< the driver took the flag
        already_on,     ///< the flag was set already
        not_supported,  ///< the driver has no serial_struct (pseudo-terminal, some USB drivers)
        refused,        ///< the driver has one but did not take (or keep) the flag
    };
    Outcome outcome = Outcome::not_requested;
    int error = 0;  ///< errno of the failing call (not_supported, refused)
};

/// Sets ASYNC_LOW_LATENCY on @p fd unless it is set, and reads it back.
[[nodiscard]] LowLatency request_low_latency(int fd, const SerialIoctls& ioctls);

/// For the log: "low latency on", "low latency: not supported by the driver (...)".
[[nodiscard]] std::string to_string(const LowLatency& result);

}  // namespace fieldbridge::engine
