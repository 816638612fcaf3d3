#include "durations.hpp"

#include <charconv>
#include <cmath>
#include <fmt/format.h>

#include "sim_error.hpp"

namespace fieldbridge::sim::runtime {

Clock::duration parse_duration(std::string_view text, DefaultUnit unit, std::string_view what) {
    const auto fail = [&](std::string_view why) {
        return SimError(fmt::format("{}: '{}' is not a duration ({}); write e.g. 500us, 1ms, "
                                    "2.5s or 1m",
                                    what, text, why));
    };
    double value = 0.0;
    const char* const begin = text.data();
    const char* const end = text.data() + text.size();
    const auto [ptr, ec] = std::from_chars(begin, end, value);
    if (ec != std::errc{} || ptr == begin) {
        throw fail("no number");
    }
    if (!std::isfinite(value) || value < 0.0) {
        throw fail("must be a finite value >= 0");
    }
    const std::string_view suffix(ptr, static_cast<std::size_t>(end - ptr));
    double ns_per_unit = 0.0;
    if (suffix.empty()) {
        switch (unit) {
            case DefaultUnit::microseconds: ns_per_unit = 1e3; break;
            case DefaultUnit::milliseconds: ns_per_unit = 1e6; break;
            case DefaultUnit::seconds: ns_per_unit = 1e9; break;
        }
    } else if (suffix == "ns") {
        ns_per_unit = 1.0;
    } else if (suffix == "us") {
        ns_per_unit = 1e3;
    } else if (suffix == "ms") {
        ns_per_unit = 1e6;
    } else if (suffix == "s") {
        ns_per_unit = 1e9;
    } else if (suffix == "m" || suffix == "min") {
        ns_per_unit = 60e9;
    } else if (suffix == "h") {
        ns_per_unit = 3600e9;
    } else {
        throw fail("unknown unit");
    }
    const double ns = value * ns_per_unit;
    // A week is far beyond any simulation; it keeps the conversion in range.
    if (ns > 7.0 * 24.0 * 3600e9) {
        throw fail("longer than a week");
    }
    return std::chrono::duration_cast<Clock::duration>(
        std::chrono::nanoseconds(static_cast<std::int64_t>(std::llround(ns))));
}

std::string format_duration(Clock::duration duration) {
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(duration).count();
    if (ns >= 1'000'000'000) {
        return fmt::format("{:.3f} s", static_cast<double>(ns) / 1e9);
    }
    if (ns >= 1'000'000) {
        return fmt::format("{:.3f} ms", static_cast<double>(ns) / 1e6);
    }
    return fmt::format("{:.1f} us", static_cast<double>(ns) / 1e3);
}

double to_us(Clock::duration duration) noexcept {
    return static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(duration).count()) /
           1e3;
}

}  // namespace fieldbridge::sim::runtime
