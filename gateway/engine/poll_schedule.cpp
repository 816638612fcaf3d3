#include "engine/poll_schedule.hpp"

#include <utility>

namespace fieldbridge::engine {

PollSchedule::PollSchedule(PollPlan plan, Duration motion_period, Duration startup_retry)
    : plan_(std::move(plan)), motion_period_(motion_period), startup_retry_(startup_retry) {
    for (const PollItem& item : plan_.items()) {
        slots_.emplace(item.id, Slot{});
    }
}

Duration PollSchedule::period_of(const PollItem& item) const noexcept {
    if (item.poll_class == PollClass::startup) {
        return Duration{};
    }
    return motion_ && item.motion ? motion_period_ : item.period;
}

std::optional<TimePoint> PollSchedule::due_of(const PollItem& item, const Slot& slot) const {
    const Duration period = period_of(item);
    // An item without a period (startup, or a block configured without one) is read
    // once, like the startup items.
    if (period <= Duration{}) {
        if (!slot.wanted) {
            return std::nullopt;
        }
        return slot.retry_at.value_or(slot.start);
    }
    return slot.slot ? *slot.slot + period : slot.start;
}

void PollSchedule::restart(TimePoint now) {
    for (auto& [id, slot] : slots_) {
        slot.wanted = true;
        slot.slot.reset();
        slot.retry_at.reset();
        slot.start = now;
    }
}

std::vector<std::uint32_t> PollSchedule::take_due(TimePoint now) {
    std::vector<std::uint32_t> out;
    for (const PollItem& item : plan_.items()) {
        Slot& slot = slots_[item.id];
        if (slot.outstanding) {
            continue;
        }
        const std::optional<TimePoint> due = due_of(item, slot);
        if (!due || *due > now) {
            continue;
        }
        const Duration period = period_of(item);
        if (period > Duration{}) {
            // Keep the cadence while the item keeps up; once it is a whole period
            // late (a busy line, a long reply), count from now instead of sending
            // the missed polls in a burst.
            slot.slot = now - *due < period ? *due : now;
        }
        slot.outstanding = true;
        slot.taken = now;
        out.push_back(item.id);
    }
    return out;
}

void PollSchedule::finished(std::uint32_t id, bool answered, TimePoint now) {
    const auto it = slots_.find(id);
    if (it == slots_.end()) {
        return;
    }
    Slot& slot = it->second;
    slot.outstanding = false;
    if (answered) {
        slot.wanted = false;
        slot.retry_at.reset();
    } else {
        slot.retry_at = now + startup_retry_;
    }
}

std::vector<PollItem> PollSchedule::reject(std::uint32_t id, TimePoint now) {
    std::vector<PollItem> split = plan_.on_block_rejected(id);
    slots_.erase(id);
    for (const PollItem& item : split) {
        Slot slot;
        slot.start = now;
        slots_.emplace(item.id, slot);
    }
    return split;
}

std::optional<TimePoint> PollSchedule::next_due() const {
    std::optional<TimePoint> earliest;
    for (const PollItem& item : plan_.items()) {
        const auto it = slots_.find(item.id);
        if (it == slots_.end() || it->second.outstanding) {
            continue;
        }
        if (const auto due = due_of(item, it->second); due && (!earliest || *due < *earliest)) {
            earliest = due;
        }
    }
    return earliest;
}

bool PollSchedule::outstanding(std::uint32_t id) const noexcept {
    const auto it = slots_.find(id);
    return it != slots_.end() && it->second.outstanding;
}

std::optional<TimePoint> PollSchedule::last_taken(std::uint32_t id) const noexcept {
    const auto it = slots_.find(id);
    return it != slots_.end() ? it->second.taken : std::nullopt;
}

}  // namespace fieldbridge::engine
