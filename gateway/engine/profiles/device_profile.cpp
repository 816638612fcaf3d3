#include "engine/profiles/device_profile.hpp"

#include <algorithm>
#include <array>

#include "engine/profiles/profile_text.hpp"

namespace fieldbridge::engine {

namespace {

[[nodiscard]] std::string hex(std::uint32_t value, int digits) {
    constexpr std::array<char, 16> symbols{'0', '1', '2', '3', '4', '5', '6', '7',
                                           '8', '9', 'A', 'B', 'C', 'D', 'E', 'F'};
    std::string out = "0x";
    for (int shift = (digits - 1) * 4; shift >= 0; shift -= 4) {
        out.push_back(symbols[(value >> shift) & 0xFU]);
    }
    return out;
}

}  // namespace

std::string hex_byte(std::uint8_t value) { return hex(value, 2); }
std::string hex_word(std::uint16_t value) { return hex(value, 4); }

std::string_view to_string(Severity severity) noexcept {
    switch (severity) {
        case Severity::warning: return "warning";
        case Severity::error: return "error";
        case Severity::critical: return "critical";
    }
    return "unknown";
}

const Field* DecodedState::find(std::string_view name) const noexcept {
    const auto it = std::find_if(fields.begin(), fields.end(), [name](const Field& f) { return f.name == name; });
    return it != fields.end() ? &*it : nullptr;
}

}  // namespace fieldbridge::engine
