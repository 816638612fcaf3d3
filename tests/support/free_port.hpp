#pragma once
/// @file free_port.hpp
/// A TCP port on 127.0.0.1 that nobody listens on now, for a test's own server (a
/// broker, socat as a device server) to bind right after.
#include <cstdint>

namespace fieldbridge::test {

/// Throws std::runtime_error when no socket can be bound.
[[nodiscard]] std::uint16_t free_loopback_port();

}  // namespace fieldbridge::test
