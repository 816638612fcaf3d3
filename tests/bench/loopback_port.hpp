#pragma once
/// @file loopback_port.hpp
/// Loopback TCP for the benchmarks: a port for a daemon to listen on, and a client's
/// connection to one.
#include <cstdint>

#include "unique_fd.hpp"

namespace fieldbridge::bench {

/// A loopback port free at the moment of asking (the daemon binds it right after).
/// Throws std::runtime_error when no port can be bound.
[[nodiscard]] std::uint16_t free_loopback_port();

/// A blocking client connection to 127.0.0.1:@p port with TCP_NODELAY (every request
/// goes out at once). Throws std::runtime_error saying what failed when it cannot.
[[nodiscard]] test_support::UniqueFd connect_loopback(std::uint16_t port);

}  // namespace fieldbridge::bench
