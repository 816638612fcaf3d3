#pragma once
/// @file broadcast_budget.hpp
/// The share of a line's time its broadcast unit may take (config `broadcast_share`,
/// docs/configuration.md): a broadcast holds the line for its frame, t3.5 and
/// `broadcast_delay`, at command priority, so without a bound one client's
/// broadcasts starve every poll and read of the line. Pure (the caller passes the
/// time).
///
/// A token bucket of line time: it fills at `share` of the time that passes, up to
/// `share` of one second, and starts full. A broadcast may start while the bucket is
/// not empty and takes its cost out (the balance may go below zero, so one broadcast
/// longer than the bucket still goes out, and the next waits until it is paid for).
/// Over any span the broadcasts of the line take at most `share` of it plus one
/// second's worth.
#include <cstdint>

#include "engine/transaction.hpp"

namespace fieldbridge::northbound {

class BroadcastBudget {
public:
    /// @p share_percent 1..100.
    explicit BroadcastBudget(unsigned share_percent) noexcept;

    /// True (and the cost is taken) when a broadcast holding the line for @p cost may
    /// start at @p now; false: over budget, nothing taken.
    [[nodiscard]] bool take(engine::Duration cost, engine::TimePoint now) noexcept;

    /// Takes the cost of a broadcast that goes out whatever the balance (a stop or
    /// e-stop, rule 4: a fairness budget never holds back a stop). The balance may go
    /// below zero: the broadcasts after it wait until the stop is paid for.
    void charge(engine::Duration cost, engine::TimePoint now) noexcept;

private:
    void refill(engine::TimePoint now) noexcept;

    unsigned share_percent_;
    engine::Duration capacity_;
    engine::Duration balance_;
    engine::TimePoint last_{};
    bool started_ = false;
};

}  // namespace fieldbridge::northbound
