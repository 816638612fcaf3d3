#include "engine/line_timing.hpp"

#include <stdexcept>
#include <string>

#include "core/error.hpp"

namespace fieldbridge::engine {
namespace {

constexpr std::uint64_t nanoseconds_per_second = 1'000'000'000;
// Modbus over Serial Line V1.02, 2.5.1.1: "for baud rates greater than 19200 Bps,
// fixed values for the 2 timers should be used: 750 us for t1.5 and 1.750 ms for t3.5".
constexpr std::uint32_t fixed_timer_baud = 19200;
constexpr std::chrono::nanoseconds fixed_t1_5{750'000};
constexpr std::chrono::nanoseconds fixed_t3_5{1'750'000};

}  // namespace

LineTiming::LineTiming(CharacterFormat format, InterFrameRule rule) : format_(format), rule_(rule) {
    if (format.baud == 0) {
        throw core::InvalidArgument("line timing: baud rate 0 is not a rate; configure the line's baud");
    }
    if (format.data_bits < 5 || format.data_bits > 8) {
        throw core::InvalidArgument("line timing: " + std::to_string(format.data_bits) +
                                    " data bits is outside 5..8");
    }
    if (format.stop_bits != 1 && format.stop_bits != 2) {
        throw core::InvalidArgument("line timing: " + std::to_string(format.stop_bits) +
                                    " stop bits; use 1 or 2");
    }
    bits_ = 1 + format.data_bits + (format.parity ? 1u : 0u) + format.stop_bits;
    if (rule == InterFrameRule::modbus_fixed_above_19200 && format.baud > fixed_timer_baud) {
        t1_5_ = fixed_t1_5;
        t3_5_ = fixed_t3_5;
    } else {
        t1_5_ = scaled(3, 2);  // 1.5 characters
        t3_5_ = scaled(7, 2);  // 3.5 characters
    }
}

std::chrono::nanoseconds LineTiming::scaled(std::uint64_t units, std::uint64_t divisor) const noexcept {
    // Exact integer arithmetic, rounded up: 256 characters x 11 bits x 1e9 is far
    // below 2^64.
    const std::uint64_t numerator = units * bits_ * nanoseconds_per_second;
    const std::uint64_t denominator = std::uint64_t{format_.baud} * divisor;
    return std::chrono::nanoseconds{
        static_cast<std::chrono::nanoseconds::rep>((numerator + denominator - 1) / denominator)};
}

std::chrono::nanoseconds LineTiming::character_time() const noexcept { return scaled(1, 1); }

std::chrono::nanoseconds LineTiming::wire_time(std::size_t characters) const noexcept {
    return scaled(characters, 1);
}

std::chrono::nanoseconds LineTiming::transaction_time(std::size_t request_bytes,
                                                      std::size_t response_bytes,
                                                      Duration device_turnaround) const noexcept {
    return wire_time(request_bytes + response_bytes) + 2 * t3_5_ +
           std::chrono::duration_cast<std::chrono::nanoseconds>(device_turnaround);
}

}  // namespace fieldbridge::engine
