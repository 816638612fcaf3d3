#include "northbound/upstream/upstream_scheduler.hpp"

#include <algorithm>
#include <fmt/format.h>

namespace fieldbridge::northbound::upstream {
namespace {

constexpr std::size_t index_of(Resource resource) noexcept { return static_cast<std::size_t>(resource); }

constexpr std::array<Resource, resource_count> all_resources{Resource::counter_read, Resource::source_view,
                                                             Resource::source_upload};

/// The function byte of a PDU, for the log (0 for an empty PDU).
std::uint8_t function_byte(const protocol::Bytes& pdu) noexcept { return protocol::pdu_function(pdu).value; }

}  // namespace

const char* to_string(UpstreamStatus status) noexcept {
    switch (status) {
        case UpstreamStatus::ok: return "ok";
        case UpstreamStatus::timeout: return "timeout";
        case UpstreamStatus::expired: return "expired";
        case UpstreamStatus::queue_full: return "queue full";
        case UpstreamStatus::path_down: return "upstream down";
        case UpstreamStatus::cancelled: return "cancelled";
    }
    return "unknown";
}

UpstreamScheduler::UpstreamScheduler(SchedulerSettings settings, engine::LogSink log)
    : settings_(settings), log_(std::move(log)) {
    settings_.window = std::max<std::size_t>(settings_.window, 1);
}

void UpstreamScheduler::submit(UpstreamRequest request, TimePoint now) {
    Entry entry;
    entry.request = std::move(request);
    entry.sequence = next_sequence_++;
    entry.enqueued = now;
    if (!entry.request.poll) {
        const auto waiting = static_cast<std::size_t>(
            std::count_if(queue_.begin(), queue_.end(), [](const Entry& e) { return !e.request.poll; }));
        if (waiting >= settings_.queue_limit) {
            log_(engine::LogLevel::warning,
                 fmt::format("upstream queue full ({} requests waiting): request FC{:02X} from client {} "
                             "refused with 0x06; raise queue_limit or poll less",
                             waiting, function_byte(entry.request.pdu), entry.request.client));
            complete(entry, UpstreamStatus::queue_full);
            return;
        }
    }
    if (entry.request.request_class.priority == engine::Priority::command) {
        entry.deadline = now + settings_.command_ttl;
    }
    queue_.push_back(std::move(entry));
}

int UpstreamScheduler::rank(const Entry& entry, TimePoint now) const {
    const RequestClass& c = entry.request.request_class;
    if (entry.request.poll) {
        // Rule 3: a poll that waited a whole period competes with on-demand reads.
        return now - entry.enqueued >= settings_.poll_period ? 2 : 3;
    }
    if (c.priority == engine::Priority::command) return c.urgent ? 0 : 1;
    return 2;
}

bool UpstreamScheduler::eligible(const Entry& entry, std::size_t index) const {
    if (entry.request.poll) return true;
    for (const Resource r : all_resources) {
        if (entry.request.request_class.role(r) == Role::none) continue;
        const Lock& lock = locks_[index_of(r)];
        if (lock.owner && *lock.owner != entry.request.client) return false;
        if (entry.request.request_class.role(r) == Role::begin && lock.owner != entry.request.client) {
            // A new set-up waits behind other clients' earlier requests to the resource.
            for (std::size_t j = 0; j < index; ++j) {
                const Entry& earlier = queue_[j];
                if (!earlier.request.poll && earlier.request.client != entry.request.client &&
                    earlier.request.request_class.role(r) != Role::none) {
                    return false;
                }
            }
        }
        // A client's own requests to one resource keep their order (its counter
        // read must not overtake its counter select, whatever their classes).
        for (std::size_t j = 0; j < index; ++j) {
            const Entry& earlier = queue_[j];
            if (!earlier.request.poll && earlier.request.client == entry.request.client &&
                earlier.request.request_class.role(r) != Role::none) {
                return false;
            }
        }
    }
    return true;
}

std::uint16_t UpstreamScheduler::allocate_transaction_id() {
    for (;;) {
        const std::uint16_t id = next_transaction_id_++;
        const bool used = std::any_of(flight_.begin(), flight_.end(),
                                      [id](const Entry& e) { return e.transaction_id == id; });
        if (!used) return id;
    }
}

std::optional<Dispatch> UpstreamScheduler::next(TimePoint now) {
    expire_commands(now);
    if (flight_.size() >= settings_.window) return std::nullopt;
    std::optional<std::size_t> best;
    int best_rank = 0;
    for (std::size_t i = 0; i < queue_.size(); ++i) {
        if (!eligible(queue_[i], i)) continue;
        const int r = rank(queue_[i], now);
        // The queue is in arrival order: the first of the best rank wins.
        if (!best || r < best_rank) {
            best = i;
            best_rank = r;
        }
    }
    if (!best) return std::nullopt;
    Entry entry = std::move(queue_[*best]);
    queue_.erase(queue_.begin() + static_cast<std::ptrdiff_t>(*best));
    entry.transaction_id = allocate_transaction_id();
    entry.sent = now;
    on_dispatch(entry, now);
    Dispatch d{entry.transaction_id, entry.request.unit, entry.request.pdu};
    if (log_.enabled(engine::LogLevel::debug)) {
        log_(engine::LogLevel::debug,
             fmt::format("upstream: sending txid {} FC{:02X} unit {} ({}, client {})", d.transaction_id,
                         function_byte(d.pdu), d.unit.value, entry.request.poll ? "poll" : "request",
                         entry.request.client));
    }
    flight_.push_back(std::move(entry));
    return d;
}

void UpstreamScheduler::on_dispatch(const Entry& entry, TimePoint now) {
    if (entry.request.poll) return;
    for (const Resource r : all_resources) {
        const Role role = entry.request.request_class.role(r);
        if (role == Role::none) continue;
        Lock& lock = locks_[index_of(r)];
        if (role == Role::begin && !lock.owner) {
            lock.owner = entry.request.client;
            lock.taken = now;
            log_(engine::LogLevel::debug,
                 fmt::format("upstream: client {} begins a {} sequence", entry.request.client, to_string(r)));
        }
        if (lock.owner == entry.request.client) {
            lock.lapses = lapse_time(lock, now + settings_.response_timeout + settings_.sequence_hold);
        }
    }
}

TimePoint UpstreamScheduler::lapse_time(const Lock& lock, TimePoint idle_until) const {
    return std::min(idle_until, lock.taken + settings_.sequence_max_hold);
}

bool UpstreamScheduler::owner_busy(Resource resource) const {
    const Lock& lock = locks_[index_of(resource)];
    return lock.owner && std::any_of(flight_.begin(), flight_.end(), [&](const Entry& e) {
               return !e.request.poll && e.request.client == *lock.owner &&
                      e.request.request_class.role(resource) != Role::none;
           });
}

void UpstreamScheduler::on_finished(const Entry& entry, bool answered, bool exception, TimePoint now) {
    if (entry.request.poll) return;
    for (const Resource r : all_resources) {
        const Role role = entry.request.request_class.role(r);
        Lock& lock = locks_[index_of(r)];
        if (role == Role::none || lock.owner != entry.request.client) continue;
        if (role == Role::finish) {
            release(r, "the sequence finished");
        } else if (role == Role::begin && (!answered || exception)) {
            // Nothing was selected (or nobody knows what was): no sequence to protect.
            release(r, answered ? "the set-up was refused" : "the set-up got no answer");
        } else if (now >= lock.taken + settings_.sequence_max_hold) {
            release(r, "held for sequence_max_hold; other clients may use it now");
        } else {
            lock.lapses = lapse_time(lock, now + settings_.sequence_hold);
        }
    }
}

void UpstreamScheduler::release(Resource resource, const char* why) {
    Lock& lock = locks_[index_of(resource)];
    if (!lock.owner) return;
    log_(engine::LogLevel::debug,
         fmt::format("upstream: client {} releases the {} ({})", *lock.owner, to_string(resource), why));
    lock.owner.reset();
}

bool UpstreamScheduler::reply(std::uint16_t transaction_id, core::UnitId unit, protocol::Bytes pdu,
                              TimePoint now) {
    const auto it = std::find_if(flight_.begin(), flight_.end(), [&](const Entry& e) {
        return e.transaction_id == transaction_id && e.request.unit == unit;
    });
    if (it == flight_.end()) {
        log_(engine::LogLevel::debug,
             fmt::format("upstream: dropped a reply with txid {} unit {}: no request waits for it "
                         "(a late answer to a timed-out request)", transaction_id, unit.value));
        return false;
    }
    Entry entry = std::move(*it);
    flight_.erase(it);
    consecutive_timeouts_ = 0;
    const core::FunctionCode asked = protocol::pdu_function(entry.request.pdu);
    const core::FunctionCode got = protocol::pdu_function(pdu);
    const bool exception = (got.value & protocol::fc::exception_flag) != 0;
    if (core::FunctionCode{static_cast<std::uint8_t>(got.value & ~protocol::fc::exception_flag)} != asked) {
        log_(engine::LogLevel::warning,
             fmt::format("upstream: reply to FC{:02X} (txid {}) carries FC{:02X}: answered 0x0B; the "
                         "upstream server is confused", asked.value, transaction_id, got.value));
        on_finished(entry, false, false, now);
        complete(entry, UpstreamStatus::timeout);
        return true;
    }
    on_finished(entry, true, exception, now);
    complete(entry, UpstreamStatus::ok, std::move(pdu));
    return true;
}

void UpstreamScheduler::expire_commands(TimePoint now) {
    for (auto it = queue_.begin(); it != queue_.end();) {
        if (it->deadline && *it->deadline <= now) {
            log_(engine::LogLevel::warning,
                 fmt::format("upstream: command FC{:02X} from client {} not sent: it waited {} ms, past "
                             "command_ttl; answered 0x0B", function_byte(it->request.pdu), it->request.client,
                             std::chrono::duration_cast<std::chrono::milliseconds>(now - it->enqueued).count()));
            complete(*it, UpstreamStatus::expired);
            it = queue_.erase(it);
        } else {
            ++it;
        }
    }
}

void UpstreamScheduler::tick(TimePoint now) {
    for (auto it = flight_.begin(); it != flight_.end();) {
        if (now - it->sent >= settings_.response_timeout) {
            ++consecutive_timeouts_;
            log_(engine::LogLevel::warning,
                 fmt::format("upstream: no reply to txid {} FC{:02X} unit {} within {} ms; answered 0x0B "
                             "(not retried)", it->transaction_id, function_byte(it->request.pdu), it->request.unit.value,
                             std::chrono::duration_cast<std::chrono::milliseconds>(settings_.response_timeout).count()));
            Entry entry = std::move(*it);
            it = flight_.erase(it);
            on_finished(entry, false, false, now);
            complete(entry, UpstreamStatus::timeout);
        } else {
            ++it;
        }
    }
    expire_commands(now);
    for (const Resource r : all_resources) {
        Lock& lock = locks_[index_of(r)];
        // A lock whose owner has a request in flight lapses when that is answered (on_finished).
        if (!lock.owner || lock.lapses > now || owner_busy(r)) continue;
        log_(engine::LogLevel::info,
             fmt::format("upstream: client {}'s {} sequence lapsed ({}); other clients may use it now",
                         *lock.owner, to_string(r),
                         now >= lock.taken + settings_.sequence_max_hold ? "held for sequence_max_hold"
                                                                         : "idle for sequence_hold"));
        lock.owner.reset();
    }
}

void UpstreamScheduler::fail_all(UpstreamStatus queued, UpstreamStatus in_flight) {
    for (Entry& e : flight_) complete(e, in_flight);
    flight_.clear();
    for (Entry& e : queue_) complete(e, queued);
    queue_.clear();
    for (Lock& lock : locks_) lock.owner.reset();
    consecutive_timeouts_ = 0;
}

void UpstreamScheduler::client_closed(std::uint64_t client) {
    std::erase_if(queue_, [client](const Entry& e) { return !e.request.poll && e.request.client == client; });
    for (Entry& e : flight_) {
        if (!e.request.poll && e.request.client == client) e.request.done = nullptr;
    }
    for (const Resource r : all_resources) {
        if (locks_[index_of(r)].owner == client) release(r, "the client closed its connection");
    }
}

std::optional<TimePoint> UpstreamScheduler::next_deadline() const {
    std::optional<TimePoint> at;
    const auto consider = [&at](TimePoint t) {
        if (!at || t < *at) at = t;
    };
    for (const Entry& e : flight_) consider(e.sent + settings_.response_timeout);
    for (const Entry& e : queue_) {
        if (e.deadline) consider(*e.deadline);
    }
    for (const Resource r : all_resources) {
        const Lock& lock = locks_[index_of(r)];
        if (lock.owner && !owner_busy(r)) consider(lock.lapses);
    }
    return at;
}

std::vector<Completion> UpstreamScheduler::take_completions() {
    std::vector<Completion> out;
    out.swap(completions_);
    return out;
}

std::optional<std::uint64_t> UpstreamScheduler::owner(Resource resource) const {
    return locks_[index_of(resource)].owner;
}

void UpstreamScheduler::complete(Entry& entry, UpstreamStatus status, protocol::Bytes pdu) {
    if (!entry.request.done) return;
    completions_.push_back({std::move(entry.request.done), {status, std::move(pdu)}});
    entry.request.done = nullptr;
}

}  // namespace fieldbridge::northbound::upstream
