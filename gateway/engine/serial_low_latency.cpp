#include "engine/serial_low_latency.hpp"

#include <linux/serial.h>
#include <sys/ioctl.h>

#include <cerrno>
#include <cstring>

namespace fieldbridge::engine {

SerialIoctls SerialIoctls::system() {
    return SerialIoctls{
        [](int fd, serial_struct& out) { return ::ioctl(fd, TIOCGSERIAL, &out) == -1 ? errno : 0; },
        [](int fd, const serial_struct& in) { return ::ioctl(fd, TIOCSSERIAL, &in) == -1 ? errno : 0; },
    };
}

LowLatency request_low_latency(int fd, const SerialIoctls& ioctls) {
    serial_struct serial{};
    if (const int error = ioctls.get(fd, serial); error != 0) {
        return {LowLatency::Outcome::not_supported, error};
    }
    if ((serial.flags & ASYNC_LOW_LATENCY) != 0) return {LowLatency::Outcome::already_on, 0};
    serial.flags |= ASYNC_LOW_LATENCY;
    if (const int error = ioctls.set(fd, serial); error != 0) {
        return {LowLatency::Outcome::refused, error};
    }
    // Some drivers accept the call and drop the flag: believe only what reads back.
    serial_struct check{};
    if (const int error = ioctls.get(fd, check); error != 0) return {LowLatency::Outcome::refused, error};
    if ((check.flags & ASYNC_LOW_LATENCY) == 0) return {LowLatency::Outcome::refused, 0};
    return {LowLatency::Outcome::enabled, 0};
}

std::string to_string(const LowLatency& result) {
    const auto reason = [&result] {
        return result.error != 0 ? std::string(" (") + std::strerror(result.error) + ")" : std::string();
    };
    switch (result.outcome) {
        case LowLatency::Outcome::not_requested: return "low latency not requested";
        case LowLatency::Outcome::enabled: return "low latency on";
        case LowLatency::Outcome::already_on: return "low latency on (already)";
        case LowLatency::Outcome::not_supported:
            return "low latency: not supported by the driver" + reason();
        case LowLatency::Outcome::refused:
            return "low latency: refused by the driver" + reason() +
                   "; a USB adapter may then add its latency timer to every reply (docs/service.md)";
    }
    return "low latency: unknown";
}

}  // namespace fieldbridge::engine
