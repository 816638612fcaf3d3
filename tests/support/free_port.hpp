#pragma once
/// @file free_port.hpp
/// A TCP port on 127.0.0.1 that nobody listens on now, for a test's own server (a
/// broker, socat as a device server) to bind right after; or a socket already
/// listening there.
#include <cstdint>

namespace fieldbridge::test {

/// Throws std::runtime_error when no socket can be bound.
[[nodiscard]] std::uint16_t free_loopback_port();

/// A socket listening on 127.0.0.1 at a port the kernel chose (backlog 1), for a
/// test's own server that accepts in-process; the caller closes `fd`.
struct LoopbackListener {
    int fd = -1;
    std::uint16_t port = 0;
};
/// Throws std::runtime_error when no socket can be bound or listen.
[[nodiscard]] LoopbackListener listen_on_loopback();

}  // namespace fieldbridge::test
