#pragma once
/// @file word_order.hpp
/// Order of the two registers of a 32-bit value on the wire (EXCD203MB: seed 002's
/// CRC-checked solm+ example is high word first; its prose says low word first).

#include <cstdint>
#include <optional>
#include <string_view>

#include "core/names.hpp"

namespace fieldbridge::core {

enum class WordOrder : std::uint8_t { high_first, low_first };

inline constexpr NameTable<WordOrder, 2> word_order_names{{
    {"high_first", WordOrder::high_first},
    {"low_first", WordOrder::low_first},
}};
template <>
struct Names<WordOrder> {
    static constexpr const auto& table = word_order_names;
};

}  // namespace fieldbridge::core
