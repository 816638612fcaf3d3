#include "northbound/targets/broadcast_budget.hpp"

#include <algorithm>
#include <chrono>

namespace fieldbridge::northbound {
namespace {

constexpr engine::Duration window = std::chrono::seconds{1};

[[nodiscard]] engine::Duration share_of(engine::Duration d, unsigned percent) noexcept {
    return d * percent / 100;
}

}  // namespace

BroadcastBudget::BroadcastBudget(unsigned share_percent) noexcept
    : share_percent_(std::clamp(share_percent, 1U, 100U)),
      capacity_(share_of(window, share_percent_)),
      balance_(capacity_) {}

void BroadcastBudget::refill(engine::TimePoint now) noexcept {
    if (!started_) {
        started_ = true;
        last_ = now;
        return;
    }
    if (now <= last_) return;
    balance_ = std::min(capacity_, balance_ + share_of(now - last_, share_percent_));
    last_ = now;
}

void BroadcastBudget::spend(engine::Duration cost) noexcept {
    balance_ = std::max(-capacity_, balance_ - cost);
}

bool BroadcastBudget::take(engine::Duration cost, engine::TimePoint now) noexcept {
    refill(now);
    if (balance_ <= engine::Duration::zero()) return false;
    spend(cost);
    return true;
}

void BroadcastBudget::charge(engine::Duration cost, engine::TimePoint now) noexcept {
    refill(now);
    spend(cost);
}

void BroadcastBudget::refund(engine::Duration cost, engine::TimePoint now) noexcept {
    refill(now);
    balance_ = std::min(capacity_, balance_ + cost);
}

engine::TimePoint BroadcastBudget::available_at(engine::TimePoint now) noexcept {
    refill(now);
    if (balance_ > engine::Duration::zero()) return now;
    // The balance grows by share_of(time passed), rounded down: positive once
    // elapsed x share / 100 >= debt + 1 tick.
    const engine::Duration::rep debt = (-balance_).count();
    const auto share = static_cast<engine::Duration::rep>(share_percent_);
    return now + engine::Duration{((debt + 1) * 100 + share - 1) / share};
}

}  // namespace fieldbridge::northbound
