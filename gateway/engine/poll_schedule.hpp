#pragma once
/// @file poll_schedule.hpp
/// When each item of one device's poll plan goes on the line (spec §3 rules 3, 5, 8).
/// Pure: no timers, no clock reads (every call takes `now`); the device agent owns
/// one, asks it what is due, and arms its timer for next_due().
///
///  - Periodic items (fast, slow, custom) are due every period, on a fixed cadence:
///    the next slot is the previous slot + period while the item keeps up, and now +
///    period once it has fallen a whole period behind (no burst of catch-up polls).
///  - Startup items are due once when the schedule (re)starts, and again
///    `startup_retry` after a failure, until one is answered.
///  - An item handed out by take_due() is outstanding until finished(): never two of
///    the same item on the line. An item that became due meanwhile is due at once
///    when it finishes.
///  - While motion is on, items flagged `motion` use the motion period.
///  - reject() applies rule 8's split (PollPlan::on_block_rejected); the halves are
///    due at once.

#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include "engine/profiles/poll_plan.hpp"
#include "engine/transaction.hpp"

namespace fieldbridge::engine {

class PollSchedule {
public:
    PollSchedule(PollPlan plan, Duration motion_period, Duration startup_retry);

    /// Every item due at @p now; startup items are wanted again (the device started
    /// or came back). Outstanding items stay outstanding.
    void restart(TimePoint now);

    /// The items due at @p now that are not outstanding, in plan order; they are
    /// outstanding from now on.
    [[nodiscard]] std::vector<std::uint32_t> take_due(TimePoint now);

    /// Item @p id is back from the line: @p answered when the device replied with
    /// something the image took (a startup item is then done), false when it failed
    /// (a startup item is retried `startup_retry` later).
    void finished(std::uint32_t id, bool answered, TimePoint now);

    /// Item @p id was answered with exception 0x02: it is replaced by its halves (due
    /// at once) or dropped. Returns the new items (empty when dropped).
    std::vector<PollItem> reject(std::uint32_t id, TimePoint now);

    /// The earliest time an item that is not outstanding is due; nullopt when none is.
    [[nodiscard]] std::optional<TimePoint> next_due() const;

    void set_motion(bool on) noexcept { motion_ = on; }
    [[nodiscard]] bool motion() const noexcept { return motion_; }
    /// The period @p item is polled at now (the motion period for motion items while
    /// motion is on); 0 for startup items.
    [[nodiscard]] Duration period_of(const PollItem& item) const noexcept;

    [[nodiscard]] const PollPlan& plan() const noexcept { return plan_; }
    [[nodiscard]] const PollItem* find(std::uint32_t id) const noexcept { return plan_.find(id); }
    [[nodiscard]] bool outstanding(std::uint32_t id) const noexcept;
    /// When item @p id was last handed out; nullopt when never (or unknown).
    [[nodiscard]] std::optional<TimePoint> last_taken(std::uint32_t id) const noexcept;

private:
    struct Slot {
        bool outstanding = false;
        bool wanted = true;                ///< startup items: not answered yet
        std::optional<TimePoint> slot;     ///< periodic: the slot of the last poll; nullopt: due at `start`
        std::optional<TimePoint> taken;    ///< when last handed out
        TimePoint start{};                 ///< due from here when there is no slot yet
        std::optional<TimePoint> retry_at; ///< startup: due again after a failure
    };

    /// When @p item is due, ignoring `outstanding`; nullopt for a startup item that is done.
    [[nodiscard]] std::optional<TimePoint> due_of(const PollItem& item, const Slot& slot) const;

    PollPlan plan_;
    Duration motion_period_;
    Duration startup_retry_;
    bool motion_ = false;
    std::map<std::uint32_t, Slot> slots_;
};

}  // namespace fieldbridge::engine
