#pragma once
/// @file register_map.hpp
/// A device's known register map: which addresses exist in which table, how wide
/// each value is (one register, a 32-bit pair, or a generic device's point of up to
/// 125 registers), who may read or write it, its
/// value range, and what writing it means (motion, stop, protected). Profiles build
/// one from their manual; validation (spec §4: 0x02 outside the map or across a
/// hole, half a pair written; 0x03 out of range) and poll planning read it.

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/register_def.hpp"
#include "engine/profiles/poll_plan.hpp"
#include "engine/register_image.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::engine {

using core::Access;
using core::can_read;
using core::can_write;
using core::RegisterDef;

/// The widest unit of a map: a point of a generic device read in one request.
inline constexpr std::uint8_t max_unit_width = 125;

/// One unit of a request: the entry it belongs to and its first address.
struct UnitRef {
    const RegisterDef* def = nullptr;
    std::uint16_t address = 0;
};

/// The table, first address and size of a read or write; the written values (bits
/// as 0 / 1) for writes. nullopt for FC07, FC17 and opaque function codes.
struct RequestSpan {
    Table table = Table::holding;
    std::uint16_t address = 0;
    std::uint16_t count = 0;
    bool write = false;
    std::vector<std::uint16_t> values;  ///< writes only
    [[nodiscard]] RegisterSpan span() const noexcept { return RegisterSpan{table, address, count}; }
};
[[nodiscard]] std::optional<RequestSpan> request_span(const protocol::Request& request);

/// The table a read function reads: FC01 coils, FC02 discrete inputs, FC04 input
/// registers, anything else (FC03) holding registers.
[[nodiscard]] Table table_of_read(core::FunctionCode function) noexcept;

/// The 32-bit value of a pair written high word first.
[[nodiscard]] constexpr std::int64_t pair_value(std::uint16_t high, std::uint16_t low, bool is_signed) noexcept {
    const std::uint32_t raw = (std::uint32_t{high} << 16) | low;
    return is_signed ? std::int64_t{static_cast<std::int32_t>(raw)} : std::int64_t{raw};
}

class RegisterMap {
public:
    RegisterMap() = default;
    /// Throws core::InvalidArgument when entries overlap, have width outside 1-125 or
    /// count 0, or run past 0xFFFF: a map is written once, in a profile's source.
    explicit RegisterMap(std::vector<RegisterDef> defs);

    /// The entry holding @p address; nullptr in a hole.
    [[nodiscard]] const RegisterDef* find(Table table, std::uint16_t address) const noexcept;

    /// 0x02 (illegal data address) when any address of the span is in a hole, or
    /// is not readable (reads) / writable (writes), or when a write starts or ends
    /// inside a pair (or a wider unit); nullopt when the span is addressable. Reading half a pair is
    /// allowed: it is harmless and some clients read one word at a time.
    [[nodiscard]] std::optional<protocol::ExceptionCode> check(Table table, std::uint16_t address,
                                                               std::uint16_t count, bool write) const;

    /// The units overlapping the span, ascending (a half-read pair is included).
    [[nodiscard]] std::vector<UnitRef> units(Table table, std::uint16_t address, std::uint16_t count) const;

    /// Poll units for @p span (which must be readable): one per map unit, so the
    /// plan can merge and split them without ever cutting a pair.
    [[nodiscard]] std::vector<PollUnit> poll_units(const RegisterSpan& span, PollClass poll_class,
                                                   Duration period, bool motion) const;

    [[nodiscard]] const std::vector<RegisterDef>& entries(Table table) const noexcept {
        return tables_[static_cast<std::size_t>(table)];
    }

private:
    std::array<std::vector<RegisterDef>, table_count> tables_{};
};

/// Checks a unit's value beyond the entry's min / max (model-dependent ranges,
/// allowed sets): 0x03 or nullopt. Called only for values inside min / max.
using ValueCheck = std::function<std::optional<protocol::ExceptionCode>(const RegisterDef& def,
                                                                        std::uint16_t unit_address,
                                                                        std::int64_t value)>;

/// The validation every map-based profile shares (spec §4), in this order:
/// 0x01 function not in @p functions; 0x03 quantity 0 or above the protocol limit;
/// 0x02 RegisterMap::check(); 0x01 a protected entry written while
/// !@p allow_protected; 0x03 a value outside its entry's min / max, or refused by
/// @p extra. Requests without a span (FC07) pass when their function is listed.
[[nodiscard]] std::optional<protocol::ExceptionCode> validate_request(const RegisterMap& map,
                                                                      const protocol::Request& request,
                                                                      std::span<const core::FunctionCode> functions,
                                                                      bool allow_protected,
                                                                      const ValueCheck& extra);

/// Every written unit with its value (pairs: the 32-bit value, high word first;
/// wider units: their first register).
struct WrittenUnit {
    const RegisterDef* def = nullptr;
    std::uint16_t address = 0;
    std::int64_t value = 0;
};
[[nodiscard]] std::vector<WrittenUnit> written_units(const RegisterMap& map, const RequestSpan& span);

/// Write / motion / urgent stop / protected / idempotent from the entries' flags.
struct Classification;
[[nodiscard]] Classification classify_request(const RegisterMap& map, const protocol::Request& request);

}  // namespace fieldbridge::engine
