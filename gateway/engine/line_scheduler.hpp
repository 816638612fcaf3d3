#pragma once
/// @file line_scheduler.hpp
/// Which transaction goes on a line next (product spec section 3). Pure: no I/O, no
/// clock reads (every call takes `now`), no threads; the line's loop thread owns it.
///
/// Order of picking, among the transactions that may go now:
///  1. urgent commands (stop / e-stop, rule 4), first come first served;
///  2. commands (rule 2);
///  3. on-demand reads, and polls that waited longer than their poll period (rule 3,
///     "aged"), in the order they entered this class: an on-demand read when it was
///     submitted, an aged poll when its period ran out (enqueued + period);
///  4. polls, oldest first.
/// Inside a class, a read re-queued for a retry goes first (rule 6), then requests to
/// live devices before an offline device's probe (rule 10), then by time.
///
/// Bounds (no class starves):
///  - a command waits for the transaction in flight and nothing else (rule 2), with one
///    exception: after `command_burst` consecutive commands picked while an on-demand
///    read or an aged poll (class 3 above) was waiting, the first of those goes once.
///    A command then waits at most for the one in flight plus one read. Urgent
///    commands are never held back.
///  - a poll waits at most its period, then competes with on-demand reads in time order.
///  - an offline device's due probe goes after live requests of its class, and
///    competes as a live request once it has been due for one more back-off interval.
///
/// Pacing: a device with a `request_gap` or a `first_request_delay` is not eligible
/// until its pacing instant (the end of its last transaction + request_gap; the line's
/// open + first_request_delay); the other devices take the line meanwhile.
///
/// Deadlines (rule 9): a transaction whose deadline has passed is completed `expired`
/// when it is submitted, and whenever the scheduler looks at its queues (next, expire).
///
/// Offline devices (rules 7, 10): `offline_after` consecutive timed-out attempts take a
/// device offline. Its queue is trimmed to the one request that would have gone first
/// (the others complete `device_offline`), and later submissions, commands included,
/// complete `device_offline` at once while it holds that one: a command would wait for
/// the probe, and its deadline is shorter than any back-off, so the client gets its
/// answer now instead of `expired` later. The held request is the probe: it becomes
/// eligible `offline_backoff.initial` after the device went offline, then after each
/// further timeout the interval doubles up to `offline_backoff.max`. Any valid reply
/// (a Modbus exception included) brings the device online at once.
///
/// Retries (rule 6): a timed-out transaction with `retry_allowed` goes back to the
/// front of its class until it has been on the wire 1 + `read_retries` times, unless
/// its device just went offline. Modbus requests whose function code may write are
/// never retried, whatever the flag says. A write that timed out completes `timeout`
/// and is logged as a warning (the device may have acted).
///
/// Every submitted transaction completes exactly once. Completions and device health
/// changes are collected, never called from inside a method (the same design as
/// northbound/upstream/upstream_scheduler.hpp): the line core hands them to its shell,
/// which calls them after the transition, so a handler may submit or stop at will.

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "engine/line_log.hpp"
#include "engine/line_stats.hpp"
#include "engine/transaction.hpp"

namespace fieldbridge::engine {

/// Number of OutcomeStatus values (for per-status counters).
inline constexpr std::size_t outcome_status_count =
    static_cast<std::size_t>(OutcomeStatus::bad_reply) + 1;
inline constexpr std::size_t priority_count = 3;

/// Per-device queue and health policy (config: device `queue_limit`, line
/// `read_retries`, `offline_after`, `offline_backoff`).
struct DeviceLimits {
    std::size_t queue_limit = 16;
    unsigned read_retries = 1;
    unsigned offline_after = 3;
    Duration backoff_initial = std::chrono::seconds{1};
    Duration backoff_max = std::chrono::seconds{30};
    /// Pacing: at least this long from the end of one of the device's transactions to
    /// the next request to it (other devices use the line meanwhile).
    Duration request_gap = Duration::zero();
    /// After the line opens or reconnects (line_opened), before the first request.
    Duration first_request_delay = Duration::zero();
};

struct SchedulerConfig {
    std::string line_name;
    /// Consecutive commands picked while an on-demand read or aged poll waits before
    /// that one goes once; 0: commands always go first.
    std::size_t command_burst = 8;
    /// Ageing period for a poll submitted without `poll_period`.
    Duration default_poll_age = std::chrono::seconds{1};
    /// Queue of the broadcast pseudo-device (`broadcast_device`), created on first use.
    std::size_t broadcast_queue_limit = 16;
};

/// Counters of one priority class of one device.
struct ClassStats {
    std::size_t depth = 0;          ///< queued now
    std::uint64_t submitted = 0;
    std::uint64_t started = 0;      ///< handed to the line by next() (retries included)
    std::uint64_t retries = 0;      ///< re-queued after a timeout
    std::array<std::uint64_t, outcome_status_count> outcomes{};  ///< completions by status
    LatencyHistogram wait;          ///< queued -> started

    [[nodiscard]] std::uint64_t outcome(OutcomeStatus status) const noexcept {
        return outcomes[static_cast<std::size_t>(status)];
    }
};

struct DeviceStats {
    std::array<ClassStats, priority_count> by_class{};  ///< indexed by Priority
    std::uint64_t went_offline = 0;
    std::uint64_t came_online = 0;
    /// Valid replies that were Modbus exception responses (the device refused).
    std::uint64_t device_exceptions = 0;

    [[nodiscard]] const ClassStats& of(Priority priority) const noexcept {
        return by_class[static_cast<std::size_t>(priority)];
    }
};

/// Online/offline transitions, for MQTT state and alarms.
using HealthCallback = std::function<void(DeviceIndex device, bool online, TimePoint now)>;

/// A transaction and its outcome, to hand to its on_done.
struct LineCompletion {
    Transaction transaction;
    Outcome outcome;
};

/// A device went offline or came back online at @p at.
struct HealthChange {
    DeviceIndex device = 0;
    bool online = true;
    TimePoint at{};
};

class LineScheduler {
public:
    explicit LineScheduler(SchedulerConfig config, LogSink log = {});

    /// Registers a device (online, empty queue). Throws core::InvalidArgument for a
    /// duplicate index, broadcast_device, or limits that cannot work (queue_limit 0,
    /// offline_after 0, back-off not positive or max below initial). @p name (the
    /// device's config name) is what the scheduler's log messages call it.
    void add_device(DeviceIndex device, DeviceLimits limits, std::string name = {});
    /// Reload: new limits for a registered device (same checks as add_device); its
    /// queue, health state and counters stay. Throws core::InvalidArgument for an
    /// unknown device.
    void update_device(DeviceIndex device, DeviceLimits limits);
    /// Reload: forgets @p device. Its queued transactions complete with @p status; one
    /// in flight still completes through finished(). Unknown devices are ignored.
    void remove_device(DeviceIndex device, OutcomeStatus status, TimePoint now);
    /// Reload: completes @p device's queued polls with @p status (its agent was
    /// retired: nobody waits for them); its other requests stay queued.
    void drop_polls(DeviceIndex device, OutcomeStatus status, TimePoint now);

    /// Queues @p transaction (sets id and enqueued), or completes it at once:
    /// `invalid_request` for an unknown device,
    /// `expired` past its deadline, `device_offline` (see above), `queue_full` beyond
    /// the device's queue_limit (Modbus TCP: exception 0x06).
    void submit(Transaction transaction, TimePoint now);

    /// The transaction to put on the line now, if any; completes expired ones first.
    /// Call only when the line is free (rule 1).
    [[nodiscard]] std::optional<Transaction> next(TimePoint now);

    /// The line master finished @p transaction: applies the retry and offline policy,
    /// then completes it (unless it is re-queued for a retry).
    void finished(Transaction transaction, const Outcome& outcome, TimePoint now);

    /// Completes @p transaction with @p status without queueing it (the line's inbox
    /// at shutdown). Not counted in the device's statistics.
    void refuse(Transaction transaction, OutcomeStatus status, TimePoint now);

    /// A submission the line turns away (its port is down: `line_down`): completed at
    /// once like a refusal of submit() (id and enqueued set, counted in the device's
    /// outcomes). The scheduler keeps no port state: the line core owns it.
    void turn_away(Transaction transaction, OutcomeStatus status, TimePoint now);

    /// When next() may have something to hand out while nothing is submitted: now if
    /// something is eligible, else the earliest probe time or deadline; nullopt when
    /// all queues are empty.
    [[nodiscard]] std::optional<TimePoint> next_wakeup(TimePoint now) const;

    /// The line's port opened at @p now: each device waits its first_request_delay.
    void line_opened(TimePoint now);

    /// Completes every queued transaction whose deadline has passed.
    void expire(TimePoint now);

    /// Completes every queued transaction with @p status (shutdown, reconfiguration).
    void cancel_all(OutcomeStatus status, TimePoint now);

    /// Completions decided since the last take, in order, appended to @p into (swapped
    /// when @p into is empty: the two buffers keep their capacity, no allocation).
    void take_completions(std::vector<LineCompletion>& into);
    /// Health changes since the last take, in order; deliver them before the
    /// completions taken with them (a device's offline notice comes before the
    /// outcomes it caused).
    void take_health_changes(std::vector<HealthChange>& into);
    [[nodiscard]] bool has_completions() const noexcept { return !completions_.empty(); }
    [[nodiscard]] bool has_health_changes() const noexcept { return !health_.empty(); }

    [[nodiscard]] bool has_device(DeviceIndex device) const noexcept;
    /// False for an unknown device.
    [[nodiscard]] bool online(DeviceIndex device) const noexcept;
    /// Nullptr for an unknown device.
    [[nodiscard]] const DeviceStats* stats(DeviceIndex device) const noexcept;
    [[nodiscard]] std::size_t queued(DeviceIndex device) const noexcept;
    [[nodiscard]] std::size_t queued() const noexcept;
    /// When an offline device's held request may go next; nullopt when online.
    [[nodiscard]] std::optional<TimePoint> probe_due(DeviceIndex device) const noexcept;
    [[nodiscard]] const SchedulerConfig& config() const noexcept { return config_; }

private:
    struct Entry {
        Transaction transaction;
        TimePoint queued_at{};  ///< submit or retry: for the wait statistics
        std::uint64_t sequence = 0;
        bool front = false;  ///< a retry: first in its class
    };
    struct Device {
        DeviceLimits limits;
        std::string name;  ///< for log messages; empty: called by its index
        std::vector<Entry> queue;  ///< unordered: next() ranks every entry
        bool online = true;
        unsigned consecutive_timeouts = 0;
        Duration backoff{};
        TimePoint probe_due{};
        TimePoint paced_until{};  ///< request_gap / first_request_delay: not before
        DeviceStats stats;
    };
    struct Rank;

    void check_limits(DeviceIndex device, const DeviceLimits& limits) const;
    [[nodiscard]] Device* find(DeviceIndex device) noexcept;
    [[nodiscard]] const Device* find(DeviceIndex device) const noexcept;
    [[nodiscard]] bool eligible(const Device& device, TimePoint now) const noexcept;
    /// When eligible() turns true by time alone (probe due, pacing).
    [[nodiscard]] static TimePoint ready_at(const Device& device) noexcept;
    [[nodiscard]] Rank rank(const Device& device, const Entry& entry, TimePoint now) const noexcept;
    [[nodiscard]] Duration poll_age(const Transaction& transaction) const noexcept;
    void sweep_expired(TimePoint now);
    void take_offline(DeviceIndex index, Device& device, TimePoint now);
    void bring_online(DeviceIndex index, Device& device, TimePoint now);
    void enqueue(Device& device, Transaction transaction, TimePoint now, bool front);
    /// Completes @p transaction with @p status (never sent).
    void reject(Transaction transaction, OutcomeStatus status, TimePoint now);
    /// Counts the outcome and collects the completion.
    void complete(Transaction transaction, const Outcome& outcome);
    [[nodiscard]] std::string describe(DeviceIndex device) const;

    SchedulerConfig config_;
    LogSink log_;
    std::map<DeviceIndex, Device> devices_;
    std::vector<LineCompletion> completions_;  ///< collected, for take_completions()
    std::vector<HealthChange> health_;         ///< collected, for take_health_changes()
    std::uint64_t next_id_ = 0;
    std::uint64_t next_sequence_ = 0;
    std::size_t consecutive_commands_ = 0;
};

}  // namespace fieldbridge::engine
