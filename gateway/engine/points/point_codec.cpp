#include "engine/points/point_codec.hpp"

#include "core/text_template.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <limits>
#include <string_view>
#include <type_traits>

namespace fieldbridge::engine::points {

namespace {

using core::ByteOrder;
using core::PointDef;
using core::PointType;
using core::WordOrder;

[[nodiscard]] std::uint16_t swap_bytes(std::uint16_t r) noexcept {
    return static_cast<std::uint16_t>(((r & 0x00FFU) << 8) | (r >> 8));
}

[[nodiscard]] bool is_float(PointType t) noexcept { return t == PointType::float32 || t == PointType::float64; }

[[nodiscard]] bool is_integer(PointType t) noexcept {
    return t != PointType::boolean && t != PointType::string && !is_float(t);
}

[[nodiscard]] bool is_bit_point(const PointDef& p) noexcept {
    return p.is_bool() && !core::is_bit_table(p.table) && p.bit.has_value();
}

/// The value's words, most significant first (byte and word order undone).
[[nodiscard]] std::uint64_t raw_bits(const PointDef& p, std::span<const std::uint16_t> registers) {
    const std::size_t width = core::registers_of(p.type);
    std::array<std::uint16_t, 4> words{};
    for (std::size_t i = 0; i < width && i < words.size(); ++i) {
        const std::uint16_t r = i < registers.size() ? registers[i] : std::uint16_t{0};
        words[i] = p.byte_order == ByteOrder::little ? swap_bytes(r) : r;
    }
    if (p.word_order == WordOrder::low_first) {
        std::reverse(words.begin(), words.begin() + static_cast<std::ptrdiff_t>(width));
    }
    std::uint64_t bits = 0;
    for (std::size_t i = 0; i < width; ++i) {
        bits = (bits << 16) | words[i];
    }
    return bits;
}

/// The registers of @p bits (the value's words, most significant first).
[[nodiscard]] std::vector<std::uint16_t> to_registers(const PointDef& p, std::uint64_t bits) {
    const std::size_t width = core::registers_of(p.type);
    std::vector<std::uint16_t> words(width);
    for (std::size_t i = 0; i < width; ++i) {
        words[width - 1 - i] = static_cast<std::uint16_t>(bits & 0xFFFFU);
        bits >>= 16;
    }
    if (p.word_order == WordOrder::low_first) {
        std::reverse(words.begin(), words.end());
    }
    if (p.byte_order == ByteOrder::little) {
        std::transform(words.begin(), words.end(), words.begin(), swap_bytes);
    }
    return words;
}

/// An integer type's raw value: signed types sign-extended, uint64 as its bits.
struct RawInteger {
    std::int64_t value = 0;
    bool above_int64 = false;  ///< uint64 above INT64_MAX: value is meaningless
    std::uint64_t unsigned_value = 0;
};

[[nodiscard]] RawInteger integer_of(const PointDef& p, std::uint64_t bits) {
    RawInteger r;
    switch (p.type) {
        case PointType::int16: r.value = static_cast<std::int16_t>(static_cast<std::uint16_t>(bits)); break;
        case PointType::uint16: r.value = static_cast<std::int64_t>(bits & 0xFFFFU); break;
        case PointType::int32: r.value = static_cast<std::int32_t>(static_cast<std::uint32_t>(bits)); break;
        case PointType::uint32: r.value = static_cast<std::int64_t>(bits & 0xFFFFFFFFU); break;
        case PointType::int64: r.value = static_cast<std::int64_t>(bits); break;
        case PointType::uint64:
            r.unsigned_value = bits;
            r.above_int64 = bits > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
            r.value = r.above_int64 ? 0 : static_cast<std::int64_t>(bits);
            break;
        default: break;
    }
    return r;
}

/// "0x" and four upper-case hex digits for each of @p registers (format: hex).
[[nodiscard]] std::string hex_text(std::uint64_t bits, std::uint16_t registers) {
    static constexpr std::string_view digits = "0123456789ABCDEF";
    std::string text = "0x";
    for (int shift = 4 * 4 * registers - 4; shift >= 0; shift -= 4) {
        text += digits[(bits >> shift) & 0xFU];
    }
    return text;
}

[[nodiscard]] std::string decode_string(const PointDef& p, std::span<const std::uint16_t> registers) {
    std::string s;
    s.reserve(std::size_t{p.count} * 2);
    for (std::size_t i = 0; i < p.count; ++i) {
        const std::uint16_t r = i < registers.size() ? registers[i] : std::uint16_t{0};
        const std::uint16_t held = p.byte_order == ByteOrder::little ? swap_bytes(r) : r;
        s.push_back(static_cast<char>(held >> 8));
        s.push_back(static_cast<char>(held & 0xFFU));
    }
    while (!s.empty() && s.back() == '\0') {
        s.pop_back();
    }
    return s;
}

/// raw × scale + offset; a scale of 1/n (0.1, 0.01) divides by n, so that 35 at 0.01
/// is 0.35, the decimal an operator expects, not 0.35000000000000003.
[[nodiscard]] double engineering(const PointDef& p, double raw) noexcept {
    if (p.scale > 0.0 && p.scale < 1.0) {
        const double divisor = std::round(1.0 / p.scale);
        if (divisor * p.scale == 1.0) {
            return raw / divisor + p.offset;
        }
    }
    return raw * p.scale + p.offset;
}

/// A format template's text: each `{i}` the register i (as int16 or uint16), `{i:hex}`
/// as "0x" and four upper-case digits.
[[nodiscard]] std::string template_text(const PointDef& p, std::span<const std::uint16_t> registers) {
    return core::expand_template(p.format_text, [&](const core::TemplateSlot& slot) -> std::string {
        std::size_t index = 0;
        for (const char c : slot.name) index = index * 10 + static_cast<std::size_t>(c - '0');
        const std::uint16_t r = index < registers.size() ? registers[index] : std::uint16_t{0};
        if (slot.hex) return hex_text(r, 1);
        return p.type == PointType::int16 ? std::to_string(static_cast<std::int16_t>(r)) : std::to_string(r);
    });
}

/// The inclusive range of an integer type's raw value, as doubles; the upper bound of
/// the 64-bit types is exclusive (2^63, 2^64: the nearest doubles above the maximum).
struct TypeRange {
    double low = 0;
    double high = 0;
    bool high_exclusive = false;
};

[[nodiscard]] TypeRange range_of(PointType t) noexcept {
    switch (t) {
        case PointType::int16: return {-32768.0, 32767.0, false};
        case PointType::uint16: return {0.0, 65535.0, false};
        case PointType::int32: return {-2147483648.0, 2147483647.0, false};
        case PointType::uint32: return {0.0, 4294967295.0, false};
        case PointType::int64: return {-9223372036854775808.0, 9223372036854775808.0, true};
        case PointType::uint64: return {0.0, 18446744073709551616.0, true};
        default: return {0.0, 1.0, false};
    }
}

[[nodiscard]] std::string number_text(double v) {
    std::array<char, 32> buf{};
    const auto [end, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), v);
    return ec == std::errc{} ? std::string(buf.data(), end) : std::string{"?"};
}

[[nodiscard]] std::string with_unit(const PointDef& p, double v) {
    return p.unit.empty() ? number_text(v) : number_text(v) + " " + p.unit;
}

/// The point's min / max refusal for @p eng ("" inside).
[[nodiscard]] std::string check_limits(const PointDef& p, double eng) {
    if (p.min && eng < *p.min) {
        return with_unit(p, eng) + " is below the minimum " + with_unit(p, *p.min);
    }
    if (p.max && eng > *p.max) {
        return with_unit(p, eng) + " is above the maximum " + with_unit(p, *p.max);
    }
    return {};
}

[[nodiscard]] std::string codes_of(const PointDef& p) {
    std::string out;
    for (const core::EnumLabel& l : p.labels) {
        out += (out.empty() ? "" : ", ") + l.label + " (" + std::to_string(l.value) + ")";
    }
    return out;
}

[[nodiscard]] std::optional<double> number_of(const PointValue& v) {
    if (const auto* i = std::get_if<std::int64_t>(&v)) return static_cast<double>(*i);
    if (const auto* d = std::get_if<double>(&v)) return *d;
    return std::nullopt;
}

[[nodiscard]] std::string_view kind_of(const PointValue& v) {
    switch (v.index()) {
        case 0: return "a boolean";
        case 1:
        case 2: return "a number";
        default: return "a string";
    }
}

[[nodiscard]] Encoded refused(std::string why) { return Encoded{{}, std::move(why)}; }

/// The raw integer @p raw of an integer type into registers (range checked).
[[nodiscard]] Encoded encode_integer_raw(const PointDef& p, std::int64_t raw) {
    const TypeRange range = range_of(p.type);
    const bool fits = p.type == PointType::int64 || p.type == PointType::uint64
                          ? (p.type == PointType::int64 || raw >= 0)
                          : static_cast<double>(raw) >= range.low && static_cast<double>(raw) <= range.high;
    if (!fits) {
        return refused("raw value " + std::to_string(raw) + " is outside the range of " +
                       std::string{core::to_string(p.type)});
    }
    return Encoded{to_registers(p, static_cast<std::uint64_t>(raw)), {}};
}

[[nodiscard]] Encoded encode_enum(const PointDef& p, const PointValue& value) {
    std::optional<std::int64_t> code;
    if (const auto* label = std::get_if<std::string>(&value)) {
        for (const core::EnumLabel& l : p.labels) {
            if (l.label == *label) code = l.value;
        }
        if (!code) return refused("'" + *label + "' is not one of its labels: " + codes_of(p));
    } else if (const auto* i = std::get_if<std::int64_t>(&value)) {
        code = *i;
    } else if (const auto* d = std::get_if<double>(&value); d != nullptr && std::isfinite(*d) &&
                                                             std::trunc(*d) == *d && std::fabs(*d) < 9.0e15) {
        code = static_cast<std::int64_t>(*d);
    } else {
        return refused("it takes a label or an integer code, not " + std::string{kind_of(value)});
    }
    if (label_of(p, *code).empty()) {
        return refused("code " + std::to_string(*code) + " has no label; its labels: " + codes_of(p));
    }
    return encode_integer_raw(p, *code);
}

[[nodiscard]] Encoded encode_string(const PointDef& p, const std::string& text) {
    const std::size_t capacity = std::size_t{p.count} * 2;
    if (text.size() > capacity) {
        return refused(std::to_string(text.size()) + " characters do not fit in " + std::to_string(p.count) +
                       " registers (at most " + std::to_string(capacity) + ")");
    }
    for (const char c : text) {
        if (static_cast<unsigned char>(c) > 0x7F || c == '\0') {
            return refused("a string point takes ASCII characters only (no NUL)");
        }
    }
    std::vector<std::uint16_t> out(p.count, 0);
    for (std::size_t i = 0; i < text.size(); ++i) {
        const auto byte = static_cast<std::uint16_t>(static_cast<unsigned char>(text[i]));
        out[i / 2] = static_cast<std::uint16_t>(out[i / 2] | (i % 2 == 0 ? byte << 8 : byte));
    }
    if (p.byte_order == ByteOrder::little) {
        std::transform(out.begin(), out.end(), out.begin(), swap_bytes);
    }
    return Encoded{std::move(out), {}};
}

[[nodiscard]] Encoded encode_number(const PointDef& p, const PointValue& value) {
    const std::optional<double> eng = number_of(value);
    if (!eng) {
        return refused("it takes a number, not " + std::string{kind_of(value)});
    }
    if (!std::isfinite(*eng)) {
        return refused("NaN and infinity cannot be written");
    }
    if (std::string why = check_limits(p, *eng); !why.empty()) {
        return refused(std::move(why));
    }
    if (p.scale == 0.0) {
        return refused("its scale is 0: no raw value gives an engineering value");
    }
    const auto* exact = std::get_if<std::int64_t>(&value);
    const bool unscaled = p.scale == 1.0 && p.offset == 0.0;
    if (p.type == PointType::float64) {
        const double raw = unscaled ? *eng : (*eng - p.offset) / p.scale;
        if (!std::isfinite(raw)) return refused(number_text(*eng) + " is outside the range of float64");
        return Encoded{to_registers(p, std::bit_cast<std::uint64_t>(raw)), {}};
    }
    if (p.type == PointType::float32) {
        const double raw = unscaled ? *eng : (*eng - p.offset) / p.scale;
        if (!std::isfinite(raw) || std::fabs(raw) > static_cast<double>(std::numeric_limits<float>::max())) {
            return refused(number_text(*eng) + " is outside the range of float32");
        }
        return Encoded{to_registers(p, std::bit_cast<std::uint32_t>(static_cast<float>(raw))), {}};
    }
    if (exact != nullptr && unscaled) {
        return encode_integer_raw(p, *exact);  // 64-bit integers stay exact
    }
    const double raw = std::round((*eng - p.offset) / p.scale);
    const TypeRange range = range_of(p.type);
    const bool fits = raw >= range.low && (range.high_exclusive ? raw < range.high : raw <= range.high);
    if (!fits) {
        return refused(with_unit(p, *eng) + " is outside the range of " + std::string{core::to_string(p.type)} +
                       (unscaled ? std::string{} : " at scale " + number_text(p.scale)));
    }
    if (p.type == PointType::uint64 && raw >= 9223372036854775808.0) {
        return Encoded{to_registers(p, static_cast<std::uint64_t>(raw)), {}};
    }
    return Encoded{to_registers(p, static_cast<std::uint64_t>(static_cast<std::int64_t>(raw))), {}};
}

}  // namespace

PointValue decode(const PointDef& point, std::span<const std::uint16_t> registers) {
    const std::uint16_t first = registers.empty() ? std::uint16_t{0} : registers.front();
    if (point.is_bool()) {
        const bool set = is_bit_point(point) ? *point.bit < 16 && ((first >> *point.bit) & 1U) != 0 : first != 0;
        return set != point.invert;
    }
    if (point.type == PointType::string) {
        return decode_string(point, registers);
    }
    if (point.format == core::PointFormat::text) {
        return template_text(point, registers);
    }
    const std::uint64_t bits = raw_bits(point, registers);
    if (point.format == core::PointFormat::hex) {
        return hex_text(bits, point.width());
    }
    if (point.type == PointType::float32) {
        return engineering(point, static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(bits))));
    }
    if (point.type == PointType::float64) {
        return engineering(point, std::bit_cast<double>(bits));
    }
    const RawInteger raw = integer_of(point, bits);
    if (!point.labels.empty() && !raw.above_int64) {
        return raw.value;  // an enum's code: the label is label_of()'s
    }
    if (raw.above_int64) {
        return engineering(point, static_cast<double>(raw.unsigned_value));
    }
    if (point.scale == 1.0 && point.offset == 0.0) {
        return raw.value;
    }
    return engineering(point, static_cast<double>(raw.value));
}

std::optional<std::int64_t> raw_integer(const PointDef& point, std::span<const std::uint16_t> registers) {
    if (point.is_bool()) {
        return std::get<bool>(decode(point, registers)) ? 1 : 0;
    }
    if (!is_integer(point.type)) {
        return std::nullopt;
    }
    const RawInteger raw = integer_of(point, raw_bits(point, registers));
    return raw.above_int64 ? std::nullopt : std::optional{raw.value};
}

Encoded encode(const PointDef& point, const PointValue& value) {
    if (point.is_bool()) {
        const auto* b = std::get_if<bool>(&value);
        if (b == nullptr) {
            return refused("it takes true or false, not " + std::string{kind_of(value)});
        }
        const bool set = *b != point.invert;
        if (is_bit_point(point)) {
            if (*point.bit > 15) {
                return refused("its bit " + std::to_string(*point.bit) + " is outside 0-15");
            }
            return Encoded{{static_cast<std::uint16_t>(set ? 1U << *point.bit : 0U)}, {}};
        }
        return Encoded{{static_cast<std::uint16_t>(set ? 1 : 0)}, {}};
    }
    if (point.type == PointType::string) {
        const auto* s = std::get_if<std::string>(&value);
        if (s == nullptr) {
            return refused("it takes a string, not " + std::string{kind_of(value)});
        }
        return encode_string(point, *s);
    }
    if (!point.labels.empty() && is_integer(point.type)) {
        return encode_enum(point, value);
    }
    return encode_number(point, value);
}

std::string check_registers(const PointDef& point, std::span<const std::uint16_t> registers) {
    if (point.is_bool() || point.type == PointType::string) {
        return {};
    }
    const PointValue value = decode(point, registers);
    if (!point.labels.empty() && is_integer(point.type)) {
        const std::optional<std::int64_t> code = raw_integer(point, registers);
        if (!code || label_of(point, *code).empty()) {
            return "code " + to_text(value) + " has no label; its labels: " + codes_of(point);
        }
        return {};
    }
    const std::optional<double> eng = number_of(value);
    if (!eng || !std::isfinite(*eng)) {
        return "NaN and infinity cannot be written";
    }
    return check_limits(point, *eng);
}

std::string_view label_of(const PointDef& point, std::int64_t code) {
    for (const core::EnumLabel& l : point.labels) {
        if (l.value == code) {
            return l.label;
        }
    }
    return {};
}

std::string enum_text(const PointDef& point, std::int64_t code) {
    if (const std::string_view label = label_of(point, code); !label.empty()) {
        return std::string{label};
    }
    return core::expand_template(point.enum_other, [&](const core::TemplateSlot& slot) {
        return slot.hex ? hex_text(static_cast<std::uint64_t>(code), point.width()) : std::to_string(code);
    });
}

std::string to_text(const PointValue& value) {
    return std::visit(
        [](const auto& v) -> std::string {
            using T = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<T, bool>) {
                return v ? "true" : "false";
            } else if constexpr (std::is_same_v<T, std::int64_t>) {
                return std::to_string(v);
            } else if constexpr (std::is_same_v<T, double>) {
                return number_text(v);
            } else {
                return "\"" + v + "\"";
            }
        },
        value);
}

}  // namespace fieldbridge::engine::points
