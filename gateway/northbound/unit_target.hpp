#pragma once
/// @file unit_target.hpp
/// What a Modbus TCP unit ID leads to (spec §4): a serial device (its DeviceAgent), a
/// line's broadcast unit, or a unit of an upstream Modbus TCP server (Huacheng R6
/// pass-through). The server decodes MBAP and the PDU (once: RequestPdu), applies
/// access control on the typed request, answers a function
/// byte of 0 or >= 0x80 itself (exception 0x01, protocol/gateway_exceptions.hpp), and
/// hands any other PDU to the target of the unit; the target answers with a response PDU (normal or
/// exception) through the handler, exactly once, on the loop thread, never from
/// inside handle().
#include <cstdint>
#include <functional>
#include <span>
#include <utility>

#include "config/net_address.hpp"
#include "core/modbus_ids.hpp"
#include "northbound/request_pdu.hpp"
#include "protocol/bytes.hpp"

namespace fieldbridge::northbound {

/// Who sent a request: stateful upstream sequences (R6 counter indirection) are kept
/// per client connection.
struct ClientRef {
    std::uint64_t connection = 0;  ///< unique for the process lifetime
    config::IpAddress address;
};

/// Receives the response PDU (function code first; an exception is fc | 0x80, code).
using PduHandler = std::function<void(protocol::Bytes response_pdu)>;

class UnitTarget {
public:
    UnitTarget() = default;
    virtual ~UnitTarget() = default;
    UnitTarget(const UnitTarget&) = delete;
    UnitTarget& operator=(const UnitTarget&) = delete;

    /// @p request: a complete PDU as received and decoded once by the server.
    virtual void handle(core::UnitId unit, const RequestPdu& request, const ClientRef& client, PduHandler done) = 0;
    /// The same for PDU bytes (tests, tools): decodes them, then handle() above.
    void handle(core::UnitId unit, protocol::ByteView request_pdu, const ClientRef& client, PduHandler done) {
        handle(unit, RequestPdu::decode(request_pdu), client, std::move(done));
    }
    /// Units whose access rules this target's requests must pass too, besides its own
    /// unit: a line's broadcast unit reaches every unit of its line.
    [[nodiscard]] virtual std::span<const core::UnitId> ruled_as() const noexcept { return {}; }
    /// The client's connection closed: drop its state, answer nothing more to it.
    virtual void client_closed(std::uint64_t /*connection*/) {}
};

}  // namespace fieldbridge::northbound
