#include "models/point_text.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <limits>

namespace fieldbridge::sim {
namespace {

using core::PointType;

[[nodiscard]] std::string type_text(const core::PointDef& point) {
    return std::string(core::to_string(point.type));
}

/// Registers of an unsigned 16/32/64-bit pattern, most significant word first.
[[nodiscard]] std::vector<std::uint16_t> words_of(std::uint64_t bits, std::uint16_t width) {
    std::vector<std::uint16_t> words(width);
    for (std::uint16_t i = 0; i < width; ++i) {
        words[width - 1 - i] = static_cast<std::uint16_t>(bits >> (16 * i));
    }
    return words;
}

/// Applies the point's word and byte orders to most-significant-first words.
void order(const core::PointDef& point, std::vector<std::uint16_t>& words) {
    if (point.word_order == core::WordOrder::low_first) {
        std::reverse(words.begin(), words.end());
    }
    if (point.byte_order == core::ByteOrder::little) {
        for (auto& word : words) word = static_cast<std::uint16_t>((word << 8) | (word >> 8));
    }
}

[[nodiscard]] bool parse_double(std::string_view text, double& value) {
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    return !text.empty() && ec == std::errc{} && ptr == text.data() + text.size() && std::isfinite(value);
}

[[nodiscard]] std::optional<bool> parse_bool(std::string_view text) {
    if (text == "true" || text == "1" || text == "on") return true;
    if (text == "false" || text == "0" || text == "off") return false;
    return std::nullopt;
}

/// The integer range of a type, as doubles.
[[nodiscard]] std::pair<double, double> limits_of(PointType type) {
    switch (type) {
        case PointType::int16: return {-32768.0, 32767.0};
        case PointType::uint16: return {0.0, 65535.0};
        case PointType::int32: return {-2147483648.0, 2147483647.0};
        case PointType::uint32: return {0.0, 4294967295.0};
        case PointType::int64: return {-9223372036854775808.0, 9223372036854774784.0};
        default: return {0.0, 18446744073709549568.0};
    }
}

[[nodiscard]] PointRegisters numeric(const core::PointDef& point, std::string_view text) {
    double value = 0;
    bool labelled = false;
    for (const auto& label : point.labels) {
        if (label.label == text) {
            value = static_cast<double>(label.value);
            labelled = true;
        }
    }
    if (!labelled && !parse_double(text, value)) {
        return {{}, "'" + std::string(text) + "' is not a number" +
                        (point.labels.empty() ? std::string() : " nor a label of the point's enum")};
    }
    const double raw = labelled ? value : (value - point.offset) / point.scale;
    std::vector<std::uint16_t> words;
    if (point.type == PointType::float32) {
        words = words_of(std::bit_cast<std::uint32_t>(static_cast<float>(raw)), 2);
    } else if (point.type == PointType::float64) {
        words = words_of(std::bit_cast<std::uint64_t>(raw), 4);
    } else {
        const double rounded = std::nearbyint(raw);
        const auto [low, high] = limits_of(point.type);
        if (rounded < low || rounded > high) {
            return {{}, std::string(text) + " is outside what a " + type_text(point) + " holds"};
        }
        const std::uint64_t bits = rounded < 0 ? static_cast<std::uint64_t>(static_cast<std::int64_t>(rounded))
                                               : static_cast<std::uint64_t>(rounded);
        words = words_of(bits, core::registers_of(point.type));
    }
    order(point, words);
    return {words, {}};
}

[[nodiscard]] PointRegisters string_value(const core::PointDef& point, std::string_view text) {
    if (text.size() > 2u * point.count) {
        return {{}, "the text has " + std::to_string(text.size()) + " characters; the point holds " +
                        std::to_string(2u * point.count)};
    }
    std::vector<std::uint16_t> words(point.count);
    for (std::size_t i = 0; i < text.size(); ++i) {
        const auto c = static_cast<std::uint8_t>(text[i]);
        const bool high = (i % 2 == 0) == (point.byte_order == core::ByteOrder::big);
        words[i / 2] = static_cast<std::uint16_t>(words[i / 2] | (high ? c << 8 : c));
    }
    return {words, {}};
}

}  // namespace

PointRegisters registers_of_text(const core::PointDef& point, std::string_view text, std::uint16_t current) {
    if (point.type == PointType::string) {
        return string_value(point, text);
    }
    if (point.format == core::PointFormat::text) {
        return {{}, "the point shows its " + std::to_string(point.count) +
                        " registers through a template; set them with set-register"};
    }
    if (point.type == PointType::boolean) {
        const auto value = parse_bool(text);
        if (!value) return {{}, "'" + std::string(text) + "' is not a bool; use true or false"};
        const bool set = *value != point.invert;  // an inverted point reads true while its bit is 0
        if (!point.bit) return {{static_cast<std::uint16_t>(set)}, {}};
        const auto mask = static_cast<std::uint16_t>(1u << *point.bit);
        return {{static_cast<std::uint16_t>(set ? current | mask : current & ~mask)}, {}};
    }
    return numeric(point, text);
}

}  // namespace fieldbridge::sim
