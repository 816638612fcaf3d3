#include "northbound/mqtt/state_throttle.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <variant>

namespace fieldbridge::northbound::mqtt {

namespace {

[[nodiscard]] std::optional<double> numeric(const engine::FieldValue& value) {
    if (const auto* i = std::get_if<std::int64_t>(&value)) {
        return static_cast<double>(*i);
    }
    if (const auto* d = std::get_if<double>(&value)) {
        return *d;
    }
    return std::nullopt;
}

/// The largest change between two lists of the same length (R6 `axes_deg`);
/// nullopt when either is no list or the lengths differ.
[[nodiscard]] std::optional<double> largest_change(const engine::FieldValue& before,
                                                   const engine::FieldValue& after) {
    const auto* a = std::get_if<std::vector<double>>(&before);
    const auto* b = std::get_if<std::vector<double>>(&after);
    if (a == nullptr || b == nullptr || a->size() != b->size()) {
        return std::nullopt;
    }
    double largest = 0.0;
    for (std::size_t i = 0; i < a->size(); ++i) {
        largest = std::max(largest, std::fabs((*b)[i] - (*a)[i]));
    }
    return largest;
}

}  // namespace

bool field_differs(const engine::Field& before, const engine::Field& after,
                   const std::map<std::string, double, std::less<>>& deadband) {
    if (before.value == after.value) {
        return false;
    }
    const auto band = deadband.find(after.name);
    if (band != deadband.end()) {
        if (const auto change = largest_change(before.value, after.value)) {
            return *change >= band->second;  // a list moves when one of its numbers does
        }
    }
    const auto a = numeric(before.value);
    const auto b = numeric(after.value);
    if (band == deadband.end() || !a || !b) {
        return true;
    }
    return std::fabs(*b - *a) >= band->second;
}

bool state_differs(const SourceState& published, const SourceState& now,
                   const std::map<std::string, double, std::less<>>& deadband) {
    if (published.online != now.online || published.quality != now.quality) {
        return true;
    }
    const auto& before = published.decoded.fields;
    const auto& after = now.decoded.fields;
    if (before.size() != after.size()) {
        return true;
    }
    for (std::size_t i = 0; i < after.size(); ++i) {
        if (before[i].name != after[i].name || field_differs(before[i], after[i], deadband)) {
            return true;
        }
    }
    // Without decoded fields the registers are the state (generic Modbus devices).
    return after.empty() && published.raw != now.raw;
}

bool StateThrottle::due(const SourceState& state, engine::TimePoint now) const {
    if (!last_) {
        return true;
    }
    if (now - last_time_ >= settings_.heartbeat) {
        return true;
    }
    return now - last_time_ >= settings_.min_interval && state_differs(*last_, state, settings_.deadband);
}

std::optional<engine::TimePoint> StateThrottle::next_check(const SourceState& state) const {
    if (!last_) {
        return std::nullopt;
    }
    if (state_differs(*last_, state, settings_.deadband)) {
        return last_time_ + settings_.min_interval;
    }
    return last_time_ + settings_.heartbeat;
}

void StateThrottle::published(SourceState state, engine::TimePoint now) {
    last_ = std::move(state);
    last_time_ = now;
}

}  // namespace fieldbridge::northbound::mqtt
