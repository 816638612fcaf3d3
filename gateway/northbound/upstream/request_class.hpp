#pragma once
/// @file request_class.hpp
/// What a pass-through request is, from its PDU alone (pure): its priority class
/// (spec §3 rule 2: any write is a command), whether it is a stop that jumps ahead of
/// other commands (rule 4), and which stateful R6 sequences it takes part in
/// (spec §5; docs/r6-passthrough.md). Which registers those are is the R6's
/// knowledge (r6_sequences.hpp): this file decodes and asks.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "engine/transaction.hpp"
#include "northbound/upstream/r6_sequences.hpp"
#include "protocol/bytes.hpp"
#include "protocol/decode_result.hpp"
#include "protocol/gateway_exceptions.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::northbound::upstream {

struct RequestClass {
    engine::Priority priority = engine::Priority::on_demand;
    bool urgent = false;  ///< stop / pause command: ahead of other queued commands
    std::array<Role, resource_count> roles{};

    [[nodiscard]] Role role(Resource resource) const noexcept {
        return roles[static_cast<std::size_t>(resource)];
    }
    [[nodiscard]] bool touches_any() const noexcept;
    bool operator==(const RequestClass&) const = default;
};

/// A request that is answered locally, never sent.
struct LocalAnswer {
    protocol::GatewayRefusal refusal = protocol::GatewayRefusal::not_a_function;
};

/// Classifies @p pdu. A PDU that does not decode is answered locally (spec §4: known
/// invalid) with protocol::refusal_for_undecodable(): 0x01 for a function code of 0 or
/// >= 0x80, 0x03 for one that cannot carry its length, byte count or quantity.
/// Unknown function codes are forwarded: a command unless the Modbus specification
/// defines them as reads (protocol::is_write), with no resource.
struct Classified {
    std::optional<RequestClass> request;  ///< set unless answered locally
    LocalAnswer local;
};
[[nodiscard]] Classified classify(protocol::ByteView pdu);
/// The same for a request already decoded (the server decodes each PDU once).
[[nodiscard]] Classified classify(const protocol::DecodeResult<protocol::Request>& decoded, protocol::ByteView pdu);

}  // namespace fieldbridge::northbound::upstream
