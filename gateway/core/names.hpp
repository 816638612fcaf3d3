#pragma once
/// @file names.hpp
/// The one spelling table of an enumeration: the configuration file, the command
/// line, logs and MQTT all read and write these names, so each enum has exactly one
/// table (beside its definition, named to it by a specialisation of Names) and the
/// one to_string / parse<E> below are lookups in it.

#include <array>
#include <cstddef>
#include <optional>
#include <string_view>
#include <utility>

namespace fieldbridge::core {

template <class E, std::size_t N>
using NameTable = std::array<std::pair<std::string_view, E>, N>;

/// The name of @p value in @p table; "unknown" for a value the table lacks.
template <class E, std::size_t N>
[[nodiscard]] constexpr std::string_view name_in(const NameTable<E, N>& table, E value) noexcept {
    for (const auto& [name, v] : table) {
        if (v == value) {
            return name;
        }
    }
    return "unknown";
}

/// The value named @p text in @p table; nullopt for any other text.
template <class E, std::size_t N>
[[nodiscard]] constexpr std::optional<E> value_in(const NameTable<E, N>& table, std::string_view text) noexcept {
    for (const auto& [name, v] : table) {
        if (name == text) {
            return v;
        }
    }
    return std::nullopt;
}

/// Specialised beside each shared enum: `static constexpr const auto& table = ...;`.
template <class E>
struct Names;

template <class E>
concept Named = requires { Names<E>::table; };

/// The spelling of @p value ("unknown" for a value without one).
template <Named E>
[[nodiscard]] constexpr std::string_view to_string(E value) noexcept {
    return name_in(Names<E>::table, value);
}

/// The value spelled @p text; nullopt for any other text.
template <Named E>
[[nodiscard]] constexpr std::optional<E> parse(std::string_view text) noexcept {
    return value_in(Names<E>::table, text);
}

}  // namespace fieldbridge::core
