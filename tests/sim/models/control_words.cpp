#include "models/control_words.hpp"

#include <charconv>

namespace fieldbridge::sim {

std::vector<std::string_view> split_words(std::string_view text) {
    std::vector<std::string_view> words;
    std::size_t i = 0;
    while (i < text.size()) {
        while (i < text.size() && (text[i] == ' ' || text[i] == '\t')) ++i;
        const std::size_t begin = i;
        while (i < text.size() && text[i] != ' ' && text[i] != '\t') ++i;
        if (i > begin) words.push_back(text.substr(begin, i - begin));
    }
    return words;
}

std::optional<std::int64_t> parse_integer(std::string_view text) {
    bool negative = false;
    if (!text.empty() && (text.front() == '-' || text.front() == '+')) {
        negative = text.front() == '-';
        text.remove_prefix(1);
    }
    int base = 10;
    if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
        base = 16;
        text.remove_prefix(2);
    }
    if (text.empty()) return std::nullopt;
    std::int64_t value = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value, base);
    if (ec != std::errc{} || end != text.data() + text.size() || value < 0) return std::nullopt;
    return negative ? -value : value;
}

std::optional<std::int64_t> parse_fixed(std::string_view text, unsigned decimals) {
    const std::size_t dot = text.find('.');
    std::string_view whole = text.substr(0, dot);
    std::string_view fraction = dot == std::string_view::npos ? std::string_view{} : text.substr(dot + 1);
    if (fraction.size() > decimals || (dot != std::string_view::npos && fraction.empty())) {
        return std::nullopt;
    }
    bool negative = false;
    if (!whole.empty() && (whole.front() == '-' || whole.front() == '+')) {
        negative = whole.front() == '-';
        whole.remove_prefix(1);
    }
    if (whole.empty()) return std::nullopt;
    std::int64_t value = 0;
    for (const char c : whole) {
        if (c < '0' || c > '9' || value > 1'000'000'000'000) return std::nullopt;
        value = value * 10 + (c - '0');
    }
    for (unsigned i = 0; i < decimals; ++i) {
        const char c = i < fraction.size() ? fraction[i] : '0';
        if (c < '0' || c > '9') return std::nullopt;
        value = value * 10 + (c - '0');
    }
    return negative ? -value : value;
}

std::string unknown_control(std::string_view device_type, std::string_view command,
                            std::string_view known) {
    return std::string(device_type) + ": unknown control command \"" + std::string(command) +
           "\"; known: " + std::string(known);
}

}  // namespace fieldbridge::sim
