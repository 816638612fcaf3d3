#pragma once
/// @file parity.hpp
/// The parity of a serial line's character format. The config file spells it
/// "none" / "even" / "odd"; libmodbus, `fieldbridge scan --parity` and the "8N1"
/// notation use the letters N / E / O.

#include <cstdint>
#include <optional>
#include <string_view>

#include "core/names.hpp"

namespace fieldbridge::core {

enum class Parity : std::uint8_t { none, even, odd };

inline constexpr NameTable<Parity, 3> parity_names{{
    {"none", Parity::none},
    {"even", Parity::even},
    {"odd", Parity::odd},
}};
template <>
struct Names<Parity> {
    static constexpr const auto& table = parity_names;
};

/// 'N', 'E' or 'O' (libmodbus's `modbus_new_rtu` argument, the "8N1" notation).
[[nodiscard]] constexpr char parity_letter(Parity parity) noexcept {
    switch (parity) {
        case Parity::none: return 'N';
        case Parity::even: return 'E';
        case Parity::odd: return 'O';
    }
    return 'N';
}
/// The inverse of parity_letter, upper or lower case; nullopt for any other letter.
[[nodiscard]] constexpr std::optional<Parity> parse_parity_letter(char letter) noexcept {
    for (const auto parity : {Parity::none, Parity::even, Parity::odd}) {
        if (letter == parity_letter(parity) || letter == parity_letter(parity) - 'A' + 'a') {
            return parity;
        }
    }
    return std::nullopt;
}

}  // namespace fieldbridge::core
