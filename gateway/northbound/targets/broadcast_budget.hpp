#pragma once
/// @file broadcast_budget.hpp
/// The share of a line's time its broadcast unit may take (config `broadcast_share`,
/// docs/configuration.md): a broadcast holds the line for its frame, t3.5 and
/// `broadcast_delay`, at command priority, so without a bound one client's
/// broadcasts starve every poll and read of the line. Pure (the caller passes the
/// time).
///
/// A token bucket of line time: it fills at `share` of the time that passes, up to
/// `share` of one second (the capacity), and starts full. A broadcast may start while
/// the bucket is not empty and takes its cost out; the balance may go below zero (one
/// broadcast longer than the bucket still goes out, and the next waits until it is
/// paid for), but never below minus the capacity, so however long a flood lasts the
/// bucket is positive again at most two seconds after it ends. Over any span the
/// broadcasts of the line take at most `share` of it plus two seconds' worth.
///
/// What is taken is a reservation: a broadcast that does not go on the line after all
/// (refused by the line's queue, expired, line down) gives its cost back (refund()),
/// so only what went on the line is charged.
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

    /// Takes @p cost whatever the balance (down to the floor, minus the capacity).
    void charge(engine::Duration cost, engine::TimePoint now) noexcept;

    /// Gives back @p cost taken for a broadcast that did not go on the line.
    void refund(engine::Duration cost, engine::TimePoint now) noexcept;

    /// The first time at or after @p now at which take() can succeed.
    [[nodiscard]] engine::TimePoint available_at(engine::TimePoint now) noexcept;

private:
    void refill(engine::TimePoint now) noexcept;
    void spend(engine::Duration cost) noexcept;

    unsigned share_percent_;
    engine::Duration capacity_;
    engine::Duration balance_;
    engine::TimePoint last_{};
    bool started_ = false;
};

}  // namespace fieldbridge::northbound
