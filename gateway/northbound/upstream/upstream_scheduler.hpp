#pragma once
/// @file upstream_scheduler.hpp
/// The queue discipline of one upstream connection, sans I/O (no socket, no clock:
/// every call takes `now`). It decides which request goes on the connection next,
/// assigns its upstream transaction ID, matches replies by that ID, and decides
/// every outcome (docs/r6-passthrough.md):
///
/// - priority classes of spec §3 rule 2 (command > on-demand read > poll), stops
///   ahead of other commands (rule 4), polls aged up after waiting one poll period
///   (rule 3), first come first served within a class;
/// - a window of requests outstanding on the connection (default 1);
/// - commands that could not start before `command_ttl` are never sent (rule 9);
/// - a request with no reply within `response_timeout` fails (0x0B), never retried;
/// - stateful R6 sequences never interleave: a client that begins one (the counter
///   ID write, the data-source set-up...: r6_sequences.hpp) holds that resource
///   until the sequence finishes, lapses (`sequence_hold` without the owner touching
///   it, or `sequence_max_hold` after it began, whatever the owner does) or the
///   client closes; meanwhile other clients' requests touching the resource wait,
///   and a client's own requests to a resource keep their order. A set-up never
///   overtakes another client's request to the same resource that came before it, so
///   a client that keeps re-selecting cannot keep a resource from the others.
///
/// Outcomes are collected, never called from inside a method: the I/O layer takes
/// them with take_completions() and calls them on the loop (so a handler may submit).
#include <array>
#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/modbus_ids.hpp"
#include "engine/line_log.hpp"
#include "engine/transaction.hpp"
#include "northbound/upstream/request_class.hpp"
#include "protocol/bytes.hpp"

namespace fieldbridge::northbound::upstream {

using engine::Duration;
using engine::TimePoint;

enum class UpstreamStatus : std::uint8_t {
    ok,          ///< the upstream answered (a Modbus exception reply is ok too)
    timeout,     ///< sent, no reply within response_timeout or the connection dropped: 0x0B
    expired,     ///< a command whose command_ttl passed before it could be sent: 0x0B
    queue_full,  ///< queue_limit requests already waiting: 0x06
    path_down,   ///< the upstream connection is not up: never sent, 0x0A
    cancelled,   ///< the target stopped: never sent, 0x0A
};
[[nodiscard]] const char* to_string(UpstreamStatus status) noexcept;

struct UpstreamOutcome {
    UpstreamStatus status = UpstreamStatus::timeout;
    protocol::Bytes response_pdu;  ///< status ok: the upstream's reply PDU, unchanged
};
using UpstreamDone = std::function<void(const UpstreamOutcome&)>;

struct UpstreamRequest {
    std::uint64_t client = 0;  ///< the client connection (ClientRef::connection)
    bool poll = false;         ///< the gateway's own state polling (no client)
    core::UnitId unit{1};      ///< the unit ID on the upstream
    protocol::Bytes pdu;
    RequestClass request_class;
    UpstreamDone done;
};

struct SchedulerSettings {
    std::size_t queue_limit = 32;  ///< client requests waiting (polls do not count)
    std::size_t window = 1;        ///< requests outstanding on the connection at once
    Duration response_timeout = std::chrono::seconds{1};
    Duration command_ttl = std::chrono::seconds{1};
    Duration poll_period = std::chrono::milliseconds{500};  ///< polls older than this are aged up
    Duration sequence_hold = std::chrono::seconds{2};       ///< an idle sequence lapses after this
    /// A sequence lapses this long after it began, however busy its owner keeps it
    /// (once its request in flight, if any, is answered).
    Duration sequence_max_hold = std::chrono::milliseconds{500};
};

/// A request to put on the connection now.
struct Dispatch {
    std::uint16_t transaction_id = 0;
    core::UnitId unit;
    protocol::Bytes pdu;
};

struct Completion {
    UpstreamDone done;
    UpstreamOutcome outcome;
};

class UpstreamScheduler {
public:
    explicit UpstreamScheduler(SchedulerSettings settings, engine::LogSink log = {});

    /// Queues @p request; a full queue completes it queue_full at once (collected).
    void submit(UpstreamRequest request, TimePoint now);
    /// The next request to send, when the window has room and one is eligible. Expired
    /// commands met on the way are completed `expired`.
    [[nodiscard]] std::optional<Dispatch> next(TimePoint now);
    /// A reply frame from the upstream. False when no request in flight has that
    /// transaction ID and unit (a late reply to a request that timed out): dropped.
    bool reply(std::uint16_t transaction_id, core::UnitId unit, protocol::Bytes pdu, TimePoint now);
    /// Response timeouts, command deadlines and lapsed sequences up to @p now.
    void tick(TimePoint now);
    /// The connection dropped or the target stops: requests in flight complete
    /// @p in_flight (they may have acted), queued ones @p queued; every sequence ends.
    void fail_all(UpstreamStatus queued, UpstreamStatus in_flight);
    /// Drops the client's queued requests unanswered, discards the answers of its
    /// requests in flight, ends its sequences.
    void client_closed(std::uint64_t client);

    /// The earliest time tick() has something to do.
    [[nodiscard]] std::optional<TimePoint> next_deadline() const;
    [[nodiscard]] std::vector<Completion> take_completions();

    [[nodiscard]] std::size_t queued() const noexcept { return queue_.size(); }
    [[nodiscard]] std::size_t in_flight() const noexcept { return flight_.size(); }
    /// Timeouts since the last reply (the I/O layer reconnects after a few).
    [[nodiscard]] unsigned consecutive_timeouts() const noexcept { return consecutive_timeouts_; }
    /// The client holding @p resource, if any.
    [[nodiscard]] std::optional<std::uint64_t> owner(Resource resource) const;
    [[nodiscard]] const SchedulerSettings& settings() const noexcept { return settings_; }

private:
    struct Entry {
        UpstreamRequest request;
        std::uint64_t sequence = 0;          ///< arrival order
        TimePoint enqueued{};
        std::optional<TimePoint> deadline;   ///< commands: must be sent before this
        std::uint16_t transaction_id = 0;    ///< in flight
        TimePoint sent{};
    };
    struct Lock {
        std::optional<std::uint64_t> owner;
        TimePoint lapses{};
        TimePoint taken{};  ///< when the owner began: the hold ends by taken + sequence_max_hold
    };

    [[nodiscard]] bool eligible(const Entry& entry, std::size_t index) const;
    [[nodiscard]] int rank(const Entry& entry, TimePoint now) const;
    [[nodiscard]] std::uint16_t allocate_transaction_id();
    void on_dispatch(const Entry& entry, TimePoint now);
    void on_finished(const Entry& entry, bool answered, bool exception, TimePoint now);
    void release(Resource resource, const char* why);
    /// The lock's lapse time after the owner's activity at @p now (capped by the maximum hold).
    [[nodiscard]] TimePoint lapse_time(const Lock& lock, TimePoint idle_until) const;
    /// The owner of @p resource has a request touching it in flight.
    [[nodiscard]] bool owner_busy(Resource resource) const;
    void complete(Entry& entry, UpstreamStatus status, protocol::Bytes pdu = {});
    void expire_commands(TimePoint now);

    SchedulerSettings settings_;
    engine::LogSink log_;
    std::deque<Entry> queue_;   ///< arrival order
    std::vector<Entry> flight_;
    std::array<Lock, resource_count> locks_{};
    std::vector<Completion> completions_;
    std::uint64_t next_sequence_ = 1;
    std::uint16_t next_transaction_id_ = 1;
    unsigned consecutive_timeouts_ = 0;
};

}  // namespace fieldbridge::northbound::upstream
