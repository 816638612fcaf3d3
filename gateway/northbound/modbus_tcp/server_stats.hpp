#pragma once
/// @file server_stats.hpp
/// Counters of the Modbus TCP server, for systemd STATUS= and the MQTT diagnostics.
/// Written and read on the loop thread only.
#include <array>
#include <cstdint>
#include <string>

namespace fieldbridge::northbound::modbus_tcp {

struct ServerStats {
    std::uint64_t connections_open = 0;      ///< now
    std::uint64_t connections_accepted = 0;  ///< since start, refused ones excluded
    std::uint64_t refused_max_connections = 0;
    std::uint64_t refused_not_allowed = 0;   ///< client outside the allow-list
    std::uint64_t refused_per_client = 0;    ///< max_connections_per_client reached for that address
    std::uint64_t requests = 0;              ///< complete MBAP frames received
    std::uint64_t responses = 0;             ///< responses queued for sending (normal and exception)
    std::uint64_t denied = 0;                ///< requests refused by an access rule
    std::uint64_t unknown_unit = 0;          ///< requests to a unit without a route
    std::uint64_t target_failures = 0;       ///< a target threw or answered an unusable PDU
    std::uint64_t late_responses = 0;        ///< answers that came after their connection closed (dropped)
    std::uint64_t closed_by_peer = 0;
    std::uint64_t closed_malformed = 0;      ///< bad protocol id, bad length, oversize, truncated
    std::uint64_t closed_frame_timeout = 0;  ///< a frame not complete within frame_timeout of its first byte
    std::uint64_t closed_output_overflow = 0;  ///< client did not read its responses
    std::uint64_t closed_idle = 0;
    std::uint64_t closed_io_error = 0;
    /// Exception responses sent, by exception code (index = code).
    std::array<std::uint64_t, 256> exceptions_by_code{};

    [[nodiscard]] std::uint64_t exceptions(std::uint8_t code) const noexcept { return exceptions_by_code[code]; }
    [[nodiscard]] std::uint64_t exceptions_total() const noexcept;
    /// One line for STATUS=: "Modbus TCP: 3 client(s), 1200 request(s), 4 exception(s), 0 closed malformed".
    [[nodiscard]] std::string summary() const;
};

}  // namespace fieldbridge::northbound::modbus_tcp
