#pragma once
/// @file register_def.hpp
/// One row of a built-in device type's register map (docs/devices.md, "Built-in
/// types"): which addresses exist, how wide each value is, who may read or write it,
/// its write range and what writing it means. The shipped definition files
/// (config/devices/<type>.yaml, `registers:`) hold these rows; the configuration reads
/// them and the engine's profiles check requests against them (engine/profiles/
/// register_map.hpp).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "core/names.hpp"
#include "core/register_table.hpp"

namespace fieldbridge::core {

enum class Access : std::uint8_t { read = 1, write = 2, read_write = 3 };

inline constexpr NameTable<Access, 3> access_names{{
    {"read", Access::read},
    {"write", Access::write},
    {"read_write", Access::read_write},
}};
template <>
struct Names<Access> {
    static constexpr const auto& table = access_names;
};

[[nodiscard]] constexpr bool can_read(Access a) noexcept { return (static_cast<unsigned>(a) & 1U) != 0; }
[[nodiscard]] constexpr bool can_write(Access a) noexcept { return (static_cast<unsigned>(a) & 2U) != 0; }

/// One entry: @p count consecutive units of @p width registers each, all alike
/// (EXCD's n01..n99 is one entry of 99 pairs). Northbound, a pair is always high
/// word first (at the lower address). A unit wider than one register is written
/// whole or not at all.
struct RegisterDef {
    RegisterTable table = RegisterTable::holding;
    std::uint16_t address = 0;
    std::uint8_t width = 1;   ///< 1; 2 for a 32-bit pair; up to 125 for a generic device's point
    std::uint16_t count = 1;  ///< units in this entry
    Access access = Access::read_write;
    bool is_signed = false;   ///< pairs: two's complement 32-bit
    std::int64_t min = 0;     ///< allowed values for writes (both ends included)
    std::int64_t max = 0xFFFF;
    std::string name;         ///< the manual's name; entries with count > 1: a prefix
    bool motion = false;      ///< writing it moves (or stops) the device: rule 5
    bool protect = false;     ///< refused with 0x01 unless allow_protected (spec §4)
    bool auto_reset = false;  ///< the device resets it to 0 after acting (XEG §3.4)
    std::optional<std::uint16_t> stop_value;  ///< writing this value is a stop (rule 4)

    [[nodiscard]] std::size_t end() const noexcept {
        return std::size_t{address} + std::size_t{width} * count;
    }
    bool operator==(const RegisterDef&) const = default;
};

}  // namespace fieldbridge::core
