#pragma once
/// @file access_control.hpp
/// Per-request access control of the Modbus TCP server (spec section 4): what a
/// request touches (function code and address ranges, from the decoded request, or
/// straight from the PDU's header fields when it does not decode) and whether the
/// configured rules let the client do it.
///
/// Pure: no I/O, no state. The PDU is not validated here. Rules fail closed: a
/// request whose registers the server cannot derive (a PDU too short for its address
/// fields, FC08, 14, 15, 18, 2B, vendor codes) counts as touching every register
/// (0x0000-0xFFFF), so a deny rule with a register range matches it and an allow
/// rule with a narrower range does not. Only FC07, 0B, 0C and 11, which read no
/// register and change nothing, have no range.
#include <cstdint>
#include <optional>

#include "config/config.hpp"
#include "core/modbus_ids.hpp"
#include "northbound/request_pdu.hpp"
#include "protocol/bytes.hpp"

namespace fieldbridge::northbound::modbus_tcp {

/// What a request touches.
struct RequestScope {
    core::FunctionCode function;  ///< the PDU's first byte (0 for an empty PDU)
    /// FC01-06, 0F, 10: the addressed coils / inputs / registers; FC22 (0x16, mask write):
    /// its register; FC17: the read range; unknown: 0x0000-0xFFFF; FC07, 0B, 0C, 11: none.
    std::optional<config::RegisterRange> first;
    /// FC17 only: the write range.
    std::optional<config::RegisterRange> second;
    bool operator==(const RequestScope&) const = default;
};

/// Derives the scope of a request PDU (function code first). A quantity of 0 counts
/// as the one addressed register and a range running past 0xFFFF ends at 0xFFFF, so
/// a malformed quantity can never make a request look smaller than what it names.
[[nodiscard]] RequestScope request_scope(protocol::ByteView pdu) noexcept;

/// The scope of a request the server decoded once (RequestPdu): from the typed
/// request when it decoded, from the header bytes (above) when it did not, so a
/// malformed PDU still fails closed. Both give the same scope for a well-formed PDU.
[[nodiscard]] RequestScope request_scope(const RequestPdu& request) noexcept;

/// The allow-list is checked at accept (ModbusTcpConfig::client_allowed); this is
/// the per-request rule check: the first matching rule decides, no match allows.
/// FC17 is allowed only when both its read and its write range are allowed.
[[nodiscard]] bool request_allowed(const config::ModbusTcpConfig& config, const config::IpAddress& client,
                                   core::UnitId unit, const RequestScope& scope) noexcept;

}  // namespace fieldbridge::northbound::modbus_tcp
