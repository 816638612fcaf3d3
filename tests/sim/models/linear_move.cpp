#include "models/linear_move.hpp"

#include <chrono>

namespace fieldbridge::sim {
namespace {

constexpr std::int64_t ns_per_s = 1'000'000'000;

std::int64_t magnitude(std::int64_t v) noexcept { return v < 0 ? -v : v; }

}  // namespace

std::int64_t distance_in(Clock::duration elapsed, std::int64_t units_per_second) noexcept {
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(elapsed).count();
    if (ns <= 0 || units_per_second <= 0) return 0;
    // Whole seconds and the remainder separately: v * ns would overflow after a few
    // hours at high pulse rates.
    return units_per_second * (ns / ns_per_s) + units_per_second * (ns % ns_per_s) / ns_per_s;
}

LinearMove::LinearMove(Clock::time_point start, std::int64_t from, std::int64_t to,
                       std::int64_t units_per_second) noexcept
    : start_(start), from_(from), to_(to), speed_(units_per_second > 0 ? units_per_second : 1),
      end_(start) {
    // Ceiling division: the move is done at the first nanosecond its distance is covered.
    const std::int64_t distance = magnitude(to_ - from_);
    const std::int64_t ns = (distance * ns_per_s + speed_ - 1) / speed_;
    end_ = start_ + std::chrono::duration_cast<Clock::duration>(std::chrono::nanoseconds(ns));
}

std::int64_t LinearMove::position_at(Clock::time_point t) const noexcept {
    if (t >= end_) return to_;
    const std::int64_t covered = distance_in(t - start_, speed_);
    return to_ >= from_ ? from_ + covered : from_ - covered;
}

}  // namespace fieldbridge::sim
