#pragma once
/// @file connection_context.hpp
/// What the Modbus TCP server shares with its connections: configuration, routes,
/// counters, log and limits. Held by shared_ptr so that a connection closed while a
/// target still holds one of its answer handlers can count that late answer safely,
/// even after the server itself is gone.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>

#include "config/config.hpp"
#include "engine/line_log.hpp"
#include "northbound/modbus_tcp/server_stats.hpp"
#include "northbound/modbus_tcp/unit_router.hpp"

namespace fieldbridge::northbound::modbus_tcp {

/// Bounds of one connection. Not in the configuration file: they protect the
/// gateway, they are not a policy an integrator tunes.
struct ServerLimits {
    /// Requests of one connection handed to targets and not yet answered. When
    /// reached, the connection stops reading its socket until one is answered
    /// (TCP flow control then slows the client down).
    std::size_t max_outstanding = 16;
    /// Response bytes waiting for a client that does not read them (beyond what the
    /// kernel's socket buffer holds). Exceeded: the connection is closed.
    std::size_t max_output_bytes = 64 * 1024;
    /// Socket read buffer; pipelined requests are framed in place (a frame is at
    /// most 260 bytes).
    std::size_t read_buffer_bytes = 4096;
};

struct ConnectionContext {
    std::shared_ptr<const config::ModbusTcpConfig> config;
    UnitRouter routes;
    ServerStats stats;
    engine::LogSink log;
    ServerLimits limits;
    /// Called once per connection when it closes; emptied when the server goes away.
    std::function<void(std::uint64_t connection)> on_closed;
};

}  // namespace fieldbridge::northbound::modbus_tcp
