#pragma once
/// @file parsed.hpp
/// The result of converting one configuration value from text: the value, or a
/// sentence saying what is wrong and what was expected.

#include <optional>
#include <string>
#include <utility>

namespace fieldbridge::config {

template <class T>
struct Parsed {
    std::optional<T> value;
    std::string error;  ///< set when value is empty: "what is wrong, what was expected"

    [[nodiscard]] static Parsed ok(T v) { return Parsed{std::move(v), {}}; }
    [[nodiscard]] static Parsed fail(std::string why) { return Parsed{std::nullopt, std::move(why)}; }
    [[nodiscard]] explicit operator bool() const noexcept { return value.has_value(); }
};

}  // namespace fieldbridge::config
