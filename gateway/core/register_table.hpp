#pragma once
/// @file register_table.hpp
/// The four Modbus data tables (Modbus Application Protocol V1.1b3 §4.3), as the
/// configuration names a generic device's blocks and as the register image keeps them.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

#include "core/names.hpp"

namespace fieldbridge::core {

/// The values index the register image's tables (0 to table_count - 1).
enum class RegisterTable : std::uint8_t { coils = 0, discrete_inputs = 1, holding = 2, input = 3 };
inline constexpr std::size_t table_count = 4;

inline constexpr NameTable<RegisterTable, table_count> register_table_names{{
    {"coils", RegisterTable::coils},
    {"discrete_inputs", RegisterTable::discrete_inputs},
    {"holding", RegisterTable::holding},
    {"input", RegisterTable::input},
}};
template <>
struct Names<RegisterTable> {
    static constexpr const auto& table = register_table_names;
};

/// Bit tables hold 0 / 1 values and are read with FC01 / FC02.
[[nodiscard]] constexpr bool is_bit_table(RegisterTable table) noexcept {
    return table == RegisterTable::coils || table == RegisterTable::discrete_inputs;
}

}  // namespace fieldbridge::core
