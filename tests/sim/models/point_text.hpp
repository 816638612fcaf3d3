#pragma once
/// @file point_text.hpp
/// The registers of a point's value as an operator types it on the simulator's
/// control socket (`set POINT VALUE`): the inverse of what the gateway decodes
/// (docs/registers.md, "Generic devices with points"): raw = (value - offset) /
/// scale, word order high_first = most significant word first (low_first reverses the
/// words), byte order little = the bytes of each register swapped, strings two ASCII
/// characters a register padded with NUL, enum labels by their code. Unlike the
/// gateway, the simulator ignores min / max: a device may hold any value.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/point.hpp"

namespace fieldbridge::sim {

struct PointRegisters {
    std::vector<std::uint16_t> registers;  ///< point.width() values; one 0/1 for a coil
    std::string error;                     ///< set when the text is no value of the point
};

/// The registers @p text gives @p point. A `bit:` point returns @p current (its
/// register) with the bit set or cleared.
[[nodiscard]] PointRegisters registers_of_text(const core::PointDef& point, std::string_view text,
                                               std::uint16_t current = 0);

}  // namespace fieldbridge::sim
