#pragma once
/// @file point_codec.hpp
/// The value of a point from its registers and the registers of a value (docs/registers.md,
/// "Generic devices with points"): pure functions over core::PointDef, no I/O.
///
/// Registers are always as the device holds them, from point.address: word order
/// `high_first` puts the most significant word in the first register (`low_first`
/// reverses all the words of the value: 2 for 32-bit types, 4 for 64-bit ones); byte
/// order `little` swaps the two bytes inside each register. Strings are two ASCII
/// characters a register (the first in the high byte for `big`), trailing NULs trimmed.
/// A `bit:` point is that bit of its register as the device holds it.
/// Nothing here depends on the host's endianness or the width of `long`.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "core/point.hpp"

namespace fieldbridge::engine::points {

/// An engineering value: bool (bool points), std::int64_t (integer types with scale 1
/// and offset 0, and enum codes), double (floats, any scaled value, uint64 above
/// INT64_MAX), std::string (string points).
using PointValue = std::variant<bool, std::int64_t, double, std::string>;

/// The value of @p point from its registers (point.width() of them, as the device holds
/// them, from point.address; for a `bit:` point the one register; for coils / discrete
/// inputs one 0/1 value). Fewer registers than the width: the registers present are
/// used and the missing ones read as 0 (callers pass whole points).
[[nodiscard]] PointValue decode(const core::PointDef& point, std::span<const std::uint16_t> registers);

/// The raw (unscaled) integer of an integer / bool point, for enum labels and `bit`
/// alarms; nullopt for floats, strings and a uint64 above INT64_MAX.
[[nodiscard]] std::optional<std::int64_t> raw_integer(const core::PointDef& point,
                                                      std::span<const std::uint16_t> registers);

/// The registers that write a value, or why not.
struct Encoded {
    std::vector<std::uint16_t> registers;
    std::string error;  ///< for operators: names the limit, not the point
    [[nodiscard]] bool ok() const noexcept { return error.empty(); }
};

/// The registers that write @p value to @p point, or why not (text naming the limit).
/// Accepts: bool for bool points; numbers (int64 or double) for numeric points,
/// (value - offset) / scale rounded to nearest for integer types, refused when NaN /
/// inf, outside the type's range, or outside the point's min / max (engineering units);
/// for an enum point a label (std::string) or one of its codes; for string points a
/// std::string of at most 2 × count ASCII bytes (padded with NUL). A `bit:` point
/// gives its register with only that bit set (or none): the caller masks it in.
[[nodiscard]] Encoded encode(const core::PointDef& point, const PointValue& value);

/// Why a write of @p registers (point.width() of them, as the device would hold them)
/// to @p point is refused: a float that is NaN or infinite, a value outside min / max
/// once decoded, or an enum code without a label; "" when it may be written. What a
/// Modbus TCP write that covers the point is checked against.
[[nodiscard]] std::string check_registers(const core::PointDef& point, std::span<const std::uint16_t> registers);

/// The label of @p code in the point's enum ("" when none).
[[nodiscard]] std::string_view label_of(const core::PointDef& point, std::int64_t code);

/// What the state shows for code @p code of an enum point: its label, else
/// `enum_other` with `{value}` / `{value:hex}` replaced by the code ("" when the point
/// has neither: the code then stands for itself).
[[nodiscard]] std::string enum_text(const core::PointDef& point, std::int64_t code);

/// @p value as an operator reads it: true, -2, 21.5, "text" (quoted, not escaped).
[[nodiscard]] std::string to_text(const PointValue& value);

}  // namespace fieldbridge::engine::points
