#include "config/scalars.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <system_error>

namespace fieldbridge::config {

namespace {

[[nodiscard]] bool is_digit(char c) noexcept { return c >= '0' && c <= '9'; }

[[nodiscard]] bool is_hex_digit(char c) noexcept {
    return is_digit(c) || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
}

[[nodiscard]] std::string quoted(std::string_view text) {
    std::string out;
    out.reserve(text.size() + 2);
    out += '\'';
    out += text;
    out += '\'';
    return out;
}

struct DurationUnit {
    std::string_view suffix;
    std::int64_t ms;
};
// Matched whole ("ms" is never "m" + "s"); docs/configuration.md writes ranges up
// to 1h and 24h, so hours are a unit too.
constexpr std::array<DurationUnit, 4> duration_units{{{"h", 3'600'000}, {"min", 60'000}, {"ms", 1}, {"s", 1'000}}};

// About 24 days: far beyond any timeout or period, and small enough that sums of a
// few durations never overflow a 64-bit count of milliseconds or nanoseconds.
constexpr double max_duration_ms = 2'147'483'647.0;

}  // namespace

Parsed<std::int64_t> parse_integer(std::string_view text) {
    const std::string_view original = text;
    if (text.empty()) {
        return Parsed<std::int64_t>::fail("empty value; expected an integer (decimal or 0x hex)");
    }
    bool negative = false;
    int base = 10;
    if (text.front() == '-') {
        negative = true;
        text.remove_prefix(1);
    }
    if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
        base = 16;
        text.remove_prefix(2);
    }
    bool all_digits = !text.empty();
    for (const char c : text) {
        all_digits = all_digits && (base == 16 ? is_hex_digit(c) : is_digit(c));
    }
    if (!all_digits || (negative && base == 16)) {
        return Parsed<std::int64_t>::fail(quoted(original) +
                                          " is not an integer; expected decimal digits or 0x followed by hex digits");
    }
    std::uint64_t magnitude = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), magnitude, base);
    constexpr auto max_magnitude = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
    if (ec == std::errc::result_out_of_range || end != text.data() + text.size() || magnitude > max_magnitude) {
        return Parsed<std::int64_t>::fail(quoted(original) + " is too large for an integer");
    }
    const auto value = static_cast<std::int64_t>(magnitude);
    return Parsed<std::int64_t>::ok(negative ? -value : value);
}

Parsed<std::chrono::milliseconds> parse_duration(std::string_view text) {
    using Result = Parsed<std::chrono::milliseconds>;
    const std::string_view original = text;
    constexpr std::string_view expected = "expected a number with a unit (ms, s, min or h), e.g. 250ms, 2s, 1min, 1h";
    if (text.empty()) {
        return Result::fail("empty value; " + std::string(expected));
    }
    if (text.front() == '-') {
        return Result::fail(quoted(original) + " is negative; durations cannot be negative");
    }
    std::size_t number_end = 0;
    while (number_end < text.size() && (is_digit(text[number_end]) || text[number_end] == '.')) {
        ++number_end;
    }
    const std::string_view number = text.substr(0, number_end);
    std::string_view unit = text.substr(number_end);
    while (!unit.empty() && unit.front() == ' ') {
        unit.remove_prefix(1);
    }
    if (number.empty()) {
        return Result::fail(quoted(original) + " is not a duration; " + std::string(expected));
    }
    if (unit.empty()) {
        return Result::fail(quoted(original) + " has no unit; durations need one: write " + std::string(number) +
                            "ms, " + std::string(number) + "s or " + std::string(number) + "min");
    }
    const DurationUnit* found = nullptr;
    for (const auto& u : duration_units) {
        if (unit == u.suffix) {
            found = &u;
        }
    }
    if (found == nullptr) {
        return Result::fail(quoted(original) + " has the unknown unit " + quoted(unit) + "; " + std::string(expected));
    }
    double value = 0.0;
    const auto [end, ec] = std::from_chars(number.data(), number.data() + number.size(), value);
    if (ec != std::errc{} || end != number.data() + number.size() || number.back() == '.') {
        return Result::fail(quoted(original) + " is not a duration; " + std::string(expected));
    }
    const double ms = value * static_cast<double>(found->ms);
    if (ms > max_duration_ms) {
        return Result::fail(quoted(original) + " is too long; durations are limited to about 24 days");
    }
    const double whole = std::round(ms);
    if (std::fabs(ms - whole) > 1e-6) {
        return Result::fail(quoted(original) + " is not a whole number of milliseconds; the resolution is 1ms");
    }
    return Result::ok(std::chrono::milliseconds{static_cast<std::int64_t>(whole)});
}

Parsed<bool> parse_bool(std::string_view text) {
    if (text == "true") {
        return Parsed<bool>::ok(true);
    }
    if (text == "false") {
        return Parsed<bool>::ok(false);
    }
    return Parsed<bool>::fail(quoted(text) + " is not a boolean; expected true or false");
}

Parsed<double> parse_number(std::string_view text) {
    double value = 0.0;
    const char* first = text.data();
    const char* last = text.data() + text.size();
    // from_chars accepts "inf"/"nan" spellings; a config number must be an ordinary one.
    bool plain = !text.empty();
    for (const char c : text) {
        plain = plain && (is_digit(c) || c == '.' || c == '-' || c == 'e' || c == 'E' || c == '+');
    }
    const auto [end, ec] = plain ? std::from_chars(first, last, value) : std::from_chars_result{first, std::errc::invalid_argument};
    if (!plain || ec != std::errc{} || end != last || !std::isfinite(value)) {
        return Parsed<double>::fail(quoted(text) + " is not a number; expected a decimal number such as 0.05");
    }
    return Parsed<double>::ok(value);
}

std::string format_duration(std::chrono::milliseconds d) {
    const auto ms = d.count();
    if (ms != 0 && ms % 60'000 == 0) {
        return std::to_string(ms / 60'000) + "min";
    }
    if (ms != 0 && ms % 1'000 == 0) {
        return std::to_string(ms / 1'000) + "s";
    }
    return std::to_string(ms) + "ms";
}

}  // namespace fieldbridge::config
