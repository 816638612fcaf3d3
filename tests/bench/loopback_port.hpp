#pragma once
/// @file loopback_port.hpp
/// A loopback TCP port for a benchmark's daemon to listen on.
#include <cstdint>

namespace fieldbridge::bench {

/// A loopback port free at the moment of asking (the daemon binds it right after).
/// Throws std::runtime_error when no port can be bound.
[[nodiscard]] std::uint16_t free_loopback_port();

}  // namespace fieldbridge::bench
