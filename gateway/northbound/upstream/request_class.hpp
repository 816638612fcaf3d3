#pragma once
/// @file request_class.hpp
/// What a pass-through request is, from its PDU alone (pure): its priority class
/// (spec §3 rule 2: any write is a command), whether it is a stop that jumps ahead of
/// other commands (rule 4), and which stateful R6 sequences it takes part in
/// (spec §5: counter read, data-source view, data-source upload; docs/r6-passthrough.md).
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "engine/transaction.hpp"
#include "protocol/bytes.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::northbound::upstream {

/// A stateful indirection of the R6: a write selects, a later request uses the selection.
enum class Resource : std::uint8_t {
    counter_read,   ///< 0x0883 ID, then read 0x0883-0x0888
    source_view,    ///< 0x7530 data source ID, then read its length at 0x7531
    source_upload,  ///< 0x7532-0x7534 set-up, then uploads from 0x7535
};
inline constexpr std::size_t resource_count = 3;
[[nodiscard]] const char* to_string(Resource resource) noexcept;

/// The part a request plays in a resource's sequence.
enum class Role : std::uint8_t {
    none,    ///< does not touch the resource
    begin,   ///< selects (writes the set-up registers): the client takes the resource
    use,     ///< touches it without ending the sequence (an upload, a stray access)
    finish,  ///< reads the result: the sequence ends when it completes
};

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
    protocol::ExceptionCode code = protocol::ExceptionCode::illegal_function;
};

/// Classifies @p pdu. A PDU that a known function code cannot carry (length, byte
/// count, quantity 0 or above the Modbus limit) is answered 0x03, a function code of
/// 0 or >= 0x80 is answered 0x01 (spec §4: answered locally when known invalid).
/// Unknown function codes are forwarded: a command unless the Modbus specification
/// defines them as reads (protocol::is_write), with no resource.
struct Classified {
    std::optional<RequestClass> request;  ///< set unless answered locally
    LocalAnswer local;
};
[[nodiscard]] Classified classify(protocol::ByteView pdu);

}  // namespace fieldbridge::northbound::upstream
