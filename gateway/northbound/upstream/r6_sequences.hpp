#pragma once
/// @file r6_sequences.hpp
/// The stateful sequences of the Huacheng R6 that must not interleave between clients
/// (spec §5; seed 004 3.1.4, 3.3.5 and section 4; docs/r6-passthrough.md) and the
/// commands that stop it (spec §3 rule 4): which registers begin, use and finish each
/// sequence. The R6's knowledge, next to its register map (r6_map.hpp); the request
/// classifier (request_class.*) asks it and names no R6 register. Pure.
#include <cstddef>
#include <cstdint>
#include <string>

namespace fieldbridge::northbound::upstream {

/// A stateful indirection of the R6: a write selects, a later request uses the selection.
enum class Resource : std::uint8_t {
    counter_read,   ///< write the counter ID, then read ID / target / current
    source_view,    ///< write the data source ID, then read its buffer length
    source_upload,  ///< write the set-up, then upload the points
};
inline constexpr std::size_t resource_count = 3;

/// The resource and the registers it covers, for the log: "counter read (0x0883-0x0888)".
[[nodiscard]] std::string to_string(Resource resource);

/// The part a request plays in a resource's sequence.
enum class Role : std::uint8_t {
    none,    ///< does not touch the resource
    begin,   ///< selects (writes the set-up registers): the client takes the resource
    use,     ///< touches it without ending the sequence (an upload, a stray access)
    finish,  ///< reads the result: the sequence ends when it completes
};

/// The holding / input register spans a request reads and writes (count 0: none).
struct RegisterAccess {
    std::uint32_t read_address = 0;
    std::uint32_t read_count = 0;
    std::uint32_t write_address = 0;
    std::uint32_t write_count = 0;
};

/// The part a request with @p access plays in @p resource's sequence. A select-then-read
/// indirection (counter read, data-source view): a write to its selection begins it, a
/// read of its block finishes it, a request that does both (FC17) uses it, any other
/// access to the block uses it. The upload has no closing request (seed 004 3.3.5: any
/// number of frames may follow the set-up): the set-up begins it, everything else in
/// the block uses it.
[[nodiscard]] Role role_in(Resource resource, const RegisterAccess& access) noexcept;

/// True when @p access writes a stop or pause command (seed 004 3.2.1): it goes ahead
/// of other queued commands.
[[nodiscard]] bool writes_stop(const RegisterAccess& access) noexcept;

}  // namespace fieldbridge::northbound::upstream
