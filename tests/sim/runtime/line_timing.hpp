#pragma once
/// @file line_timing.hpp
/// Character and silence times of an emulated serial line. Computed from the byte
/// count each time (never by adding rounded per-character times) so long frames do
/// not accumulate rounding.

#include <chrono>
#include <cstddef>
#include <cstdint>

namespace fieldbridge::sim::runtime {

struct LineTiming {
    unsigned baud = 115200;
    /// 10 at 8N1; 11 with parity or 2 stop bits (Modbus over Serial Line V1.02, 2.5.1).
    unsigned bits_per_character = 10;

    /// Time @p bytes occupy the wire, rounded up to the nanosecond.
    [[nodiscard]] constexpr std::chrono::nanoseconds bytes(std::size_t count) const noexcept {
        const auto bits = static_cast<std::uint64_t>(count) * bits_per_character;
        return std::chrono::nanoseconds(
            static_cast<std::int64_t>((bits * 1'000'000'000ULL + baud - 1) / baud));
    }
    [[nodiscard]] constexpr std::chrono::nanoseconds character() const noexcept { return bytes(1); }
    /// t3.5 = 3.5 character times. The product spec (section 9) uses 3.5·tc at every
    /// baud rate, including above 19200 where Modbus over Serial Line fixes 1.75 ms.
    [[nodiscard]] constexpr std::chrono::nanoseconds silence() const noexcept {
        const auto bits = static_cast<std::uint64_t>(bits_per_character) * 35;
        return std::chrono::nanoseconds(
            static_cast<std::int64_t>((bits * 100'000'000ULL + baud - 1) / baud));
    }
};

}  // namespace fieldbridge::sim::runtime
