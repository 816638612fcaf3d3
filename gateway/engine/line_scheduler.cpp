#include "engine/line_scheduler.hpp"

#include <algorithm>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "core/error.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::engine {
namespace {

/// Picking tiers (see the header): smaller goes first.
enum Tier : int { urgent_command = 0, command = 1, on_demand_or_aged = 2, poll = 3 };

std::size_t class_index(Priority priority) noexcept { return static_cast<std::size_t>(priority); }

/// Rule 6 safety net: whatever the flag says, a Modbus function code that may write
/// is never repeated (is_write counts unknown codes as writes).
bool may_retry(const Transaction& transaction) noexcept {
    if (!transaction.retry_allowed) return false;
    if (const auto* modbus = std::get_if<ModbusPayload>(&transaction.payload)) {
        return !protocol::is_write(protocol::function_code(modbus->request));
    }
    return true;
}

/// For the log: a request that may have changed the device.
bool may_write(const Transaction& transaction) noexcept {
    if (const auto* modbus = std::get_if<ModbusPayload>(&transaction.payload)) {
        return protocol::is_write(protocol::function_code(modbus->request));
    }
    return !transaction.retry_allowed;
}

std::string milliseconds_text(Duration value) {
    return std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(value).count()) + " ms";
}

}  // namespace

struct LineScheduler::Rank {
    int tier = poll;
    int order = 1;    ///< 0: a retry, first in its class
    int penalty = 0;  ///< 1: an offline device's probe, after live requests
    TimePoint class_time{};
    std::uint64_t sequence = 0;

    bool operator<(const Rank& other) const noexcept {
        return std::tie(tier, order, penalty, class_time, sequence) <
               std::tie(other.tier, other.order, other.penalty, other.class_time, other.sequence);
    }
};

LineScheduler::LineScheduler(SchedulerConfig config, LogSink log)
    : config_(std::move(config)), log_(std::move(log)) {}

void LineScheduler::check_limits(DeviceIndex device, const DeviceLimits& limits) const {
    const std::string where = "line " + config_.line_name + " device " + std::to_string(device);
    if (device == broadcast_device) {
        throw core::InvalidArgument(where + ": index is reserved for broadcasts");
    }
    if (limits.queue_limit == 0) throw core::InvalidArgument(where + ": queue_limit must be at least 1");
    if (limits.offline_after == 0) {
        throw core::InvalidArgument(where + ": offline_after must be at least 1 timeout");
    }
    if (limits.backoff_initial <= Duration::zero() || limits.backoff_max < limits.backoff_initial) {
        throw core::InvalidArgument(where + ": offline back-off needs 0 < initial <= max");
    }
}

void LineScheduler::add_device(DeviceIndex device, DeviceLimits limits, std::string name) {
    check_limits(device, limits);
    if (devices_.count(device) != 0) {
        throw core::InvalidArgument("line " + config_.line_name + " device " + std::to_string(device) +
                                    ": added twice");
    }
    Device state;
    state.limits = limits;
    state.name = std::move(name);
    state.backoff = limits.backoff_initial;
    devices_.emplace(device, std::move(state));
}

void LineScheduler::update_device(DeviceIndex device, DeviceLimits limits) {
    check_limits(device, limits);
    Device* known = find(device);
    if (known == nullptr) {
        throw core::InvalidArgument("line " + config_.line_name + " device " + std::to_string(device) +
                                    ": cannot update a device that was never added");
    }
    known->limits = limits;
    // The current back-off stays inside the new bounds; the next step starts from them.
    known->backoff = std::clamp(known->backoff, limits.backoff_initial, limits.backoff_max);
}

void LineScheduler::remove_device(DeviceIndex device, OutcomeStatus status, TimePoint now) {
    const auto it = devices_.find(device);
    if (it == devices_.end()) return;
    for (Entry& entry : it->second.queue) reject(std::move(entry.transaction), status, now);
    devices_.erase(it);
}

void LineScheduler::drop_polls(DeviceIndex device, OutcomeStatus status, TimePoint now) {
    Device* known = find(device);
    if (known == nullptr) return;
    auto& queue = known->queue;
    const auto polls = std::stable_partition(queue.begin(), queue.end(), [](const Entry& entry) {
        return entry.transaction.priority != Priority::poll;
    });
    for (auto it = polls; it != queue.end(); ++it) {
        --known->stats.by_class[class_index(it->transaction.priority)].depth;
        reject(std::move(it->transaction), status, now);
    }
    queue.erase(polls, queue.end());
}

LineScheduler::Device* LineScheduler::find(DeviceIndex device) noexcept {
    const auto it = devices_.find(device);
    return it == devices_.end() ? nullptr : &it->second;
}

const LineScheduler::Device* LineScheduler::find(DeviceIndex device) const noexcept {
    const auto it = devices_.find(device);
    return it == devices_.end() ? nullptr : &it->second;
}

std::string LineScheduler::describe(DeviceIndex device) const {
    if (device == broadcast_device) return "line " + config_.line_name + " broadcast";
    if (const Device* known = find(device); known != nullptr && !known->name.empty()) {
        return "line " + config_.line_name + " device '" + known->name + "'";
    }
    return "line " + config_.line_name + " device " + std::to_string(device);
}

Duration LineScheduler::poll_age(const Transaction& transaction) const noexcept {
    return transaction.poll_period.value_or(config_.default_poll_age);
}

bool LineScheduler::eligible(const Device& device, TimePoint now) const noexcept {
    return (device.online || now >= device.probe_due) && now >= device.paced_until;
}

TimePoint LineScheduler::ready_at(const Device& device) noexcept {
    return device.online ? device.paced_until : std::max(device.probe_due, device.paced_until);
}

void LineScheduler::line_opened(TimePoint now) {
    for (auto& [index, device] : devices_) {
        device.paced_until = std::max(device.paced_until, now + device.limits.first_request_delay);
    }
}

LineScheduler::Rank LineScheduler::rank(const Device& device, const Entry& entry,
                                        TimePoint now) const noexcept {
    const Transaction& t = entry.transaction;
    Rank r;
    r.sequence = entry.sequence;
    r.order = entry.front ? 0 : 1;
    r.class_time = t.enqueued;
    switch (t.priority) {
        case Priority::command:
            r.tier = t.urgent ? urgent_command : command;
            break;
        case Priority::on_demand:
            r.tier = on_demand_or_aged;
            break;
        case Priority::poll: {
            const Duration age = poll_age(t);
            if (now - t.enqueued > age) {
                // Rule 3: it joined the on-demand class when its period ran out.
                r.tier = on_demand_or_aged;
                r.class_time = t.enqueued + age;
            } else {
                r.tier = poll;
            }
            break;
        }
    }
    // Rule 10: live devices first, until the probe has waited one more interval.
    r.penalty = (!device.online && now < device.probe_due + device.backoff) ? 1 : 0;
    return r;
}

namespace {

Outcome outcome_of(const Transaction& transaction, OutcomeStatus status, TimePoint now) {
    Outcome outcome;
    outcome.status = status;
    outcome.finished = now;
    outcome.attempts = transaction.attempts;
    return outcome;
}

}  // namespace

void LineScheduler::reject(Transaction transaction, OutcomeStatus status, TimePoint now) {
    const Outcome outcome = outcome_of(transaction, status, now);
    complete(std::move(transaction), outcome);
}

void LineScheduler::refuse(Transaction transaction, OutcomeStatus status, TimePoint now) {
    Outcome outcome = outcome_of(transaction, status, now);
    completions_.push_back(LineCompletion{std::move(transaction), std::move(outcome)});
}

void LineScheduler::turn_away(Transaction transaction, OutcomeStatus status, TimePoint now) {
    transaction.id = ++next_id_;
    transaction.enqueued = now;
    reject(std::move(transaction), status, now);
}

void LineScheduler::complete(Transaction transaction, const Outcome& outcome) {
    if (Device* device = find(transaction.device)) {
        ++device->stats.by_class[class_index(transaction.priority)].outcomes[static_cast<std::size_t>(outcome.status)];
    }
    completions_.push_back(LineCompletion{std::move(transaction), outcome});
}

void LineScheduler::take_completions(std::vector<LineCompletion>& into) {
    if (into.empty()) {
        into.swap(completions_);
        return;
    }
    for (LineCompletion& completion : completions_) into.push_back(std::move(completion));
    completions_.clear();
}

void LineScheduler::take_health_changes(std::vector<HealthChange>& into) {
    if (into.empty()) {
        into.swap(health_);
        return;
    }
    into.insert(into.end(), health_.begin(), health_.end());
    health_.clear();
}

void LineScheduler::enqueue(Device& device, Transaction transaction, TimePoint now, bool front) {
    auto& stats = device.stats.by_class[class_index(transaction.priority)];
    ++stats.depth;
    device.queue.push_back(Entry{std::move(transaction), now, next_sequence_++, front});
}

void LineScheduler::submit(Transaction transaction, TimePoint now) {
    transaction.id = ++next_id_;
    transaction.enqueued = now;
    Device* device = find(transaction.device);
    if (device == nullptr && is_broadcast(transaction)) {
        Device pseudo;
        pseudo.limits.queue_limit = config_.broadcast_queue_limit;
        pseudo.backoff = pseudo.limits.backoff_initial;
        device = &devices_.emplace(broadcast_device, std::move(pseudo)).first->second;
    }
    if (device == nullptr) {
        log_(LogLevel::error, describe(transaction.device) +
                                  ": request for a device this line does not have; not sent");
        reject(std::move(transaction), OutcomeStatus::invalid_request, now);
    } else if (transaction.deadline && now >= *transaction.deadline) {
        reject(std::move(transaction), OutcomeStatus::expired, now);
    } else if (!device->online && !device->queue.empty()) {
        reject(std::move(transaction), OutcomeStatus::device_offline, now);
    } else if (device->queue.size() >= device->limits.queue_limit) {
        reject(std::move(transaction), OutcomeStatus::queue_full, now);
    } else {
        ++device->stats.by_class[class_index(transaction.priority)].submitted;
        enqueue(*device, std::move(transaction), now, false);
    }
}

void LineScheduler::sweep_expired(TimePoint now) {
    for (auto& [index, device] : devices_) {
        auto& queue = device.queue;
        for (std::size_t i = 0; i < queue.size();) {
            const auto& deadline = queue[i].transaction.deadline;
            if (deadline && now >= *deadline) {
                --device.stats.by_class[class_index(queue[i].transaction.priority)].depth;
                reject(std::move(queue[i].transaction), OutcomeStatus::expired, now);
                queue.erase(queue.begin() + static_cast<std::ptrdiff_t>(i));
            } else {
                ++i;
            }
        }
    }
}

void LineScheduler::expire(TimePoint now) { sweep_expired(now); }

std::optional<Transaction> LineScheduler::next(TimePoint now) {
    sweep_expired(now);

    struct Choice {
        Device* device = nullptr;
        std::size_t index = 0;
        Rank rank;
    };
    std::optional<Choice> best;
    std::optional<Choice> best_read;  // best of tier on_demand_or_aged
    for (auto& [index, device] : devices_) {
        if (!eligible(device, now)) continue;
        for (std::size_t i = 0; i < device.queue.size(); ++i) {
            const Rank r = rank(device, device.queue[i], now);
            if (!best || r < best->rank) best = Choice{&device, i, r};
            if (r.tier == on_demand_or_aged && (!best_read || r < best_read->rank)) {
                best_read = Choice{&device, i, r};
            }
        }
    }

    std::optional<Transaction> picked;
    if (best) {
        Choice choice = *best;
        if (best->rank.tier <= command && best_read) {
            // Fairness bound: after command_burst commands in a row, a waiting read goes
            // once (urgent commands are never held back).
            if (best->rank.tier == command && config_.command_burst > 0 &&
                consecutive_commands_ >= config_.command_burst) {
                choice = *best_read;
                consecutive_commands_ = 0;
            } else {
                ++consecutive_commands_;
            }
        } else {
            consecutive_commands_ = 0;
        }
        auto& queue = choice.device->queue;
        Entry entry = std::move(queue[choice.index]);
        queue.erase(queue.begin() + static_cast<std::ptrdiff_t>(choice.index));
        auto& stats = choice.device->stats.by_class[class_index(entry.transaction.priority)];
        --stats.depth;
        ++stats.started;
        stats.wait.record(now - entry.queued_at);
        picked = std::move(entry.transaction);
    }
    return picked;
}

void LineScheduler::take_offline(DeviceIndex index, Device& device, TimePoint now) {
    device.online = false;
    device.backoff = device.limits.backoff_initial;
    device.probe_due = now + device.backoff;
    ++device.stats.went_offline;
    // Rule 10: a dead device holds at most one request: keep the one that would go first.
    if (device.queue.size() > 1) {
        std::size_t keep = 0;
        for (std::size_t i = 1; i < device.queue.size(); ++i) {
            if (rank(device, device.queue[i], now) < rank(device, device.queue[keep], now)) keep = i;
        }
        for (std::size_t i = 0; i < device.queue.size(); ++i) {
            if (i == keep) continue;
            --device.stats.by_class[class_index(device.queue[i].transaction.priority)].depth;
            reject(std::move(device.queue[i].transaction), OutcomeStatus::device_offline, now);
        }
        Entry kept = std::move(device.queue[keep]);
        device.queue.clear();
        device.queue.push_back(std::move(kept));
    }
    log_(LogLevel::warning, describe(index) + ": offline after " +
                                std::to_string(device.consecutive_timeouts) +
                                " consecutive timeouts; probing every " +
                                milliseconds_text(device.backoff) + " to " +
                                milliseconds_text(device.limits.backoff_max) +
                                "; check its power, wiring, address and baud rate");
    health_.push_back(HealthChange{index, false, now});
}

void LineScheduler::bring_online(DeviceIndex index, Device& device, TimePoint now) {
    device.online = true;
    device.backoff = device.limits.backoff_initial;
    ++device.stats.came_online;
    log_(LogLevel::info, describe(index) + ": answering again, back online");
    health_.push_back(HealthChange{index, true, now});
}

void LineScheduler::finished(Transaction transaction, const Outcome& outcome, TimePoint now) {
    Device* device = find(transaction.device);
    if (device == nullptr || is_broadcast(transaction)) {
        complete(std::move(transaction), outcome);
        return;
    }
    // Pacing counts from the end of the device's last transaction on the wire.
    if (transaction.attempts > 0) device->paced_until = now + device->limits.request_gap;
    const DeviceIndex index = transaction.device;
    if (outcome.status == OutcomeStatus::ok || outcome.status == OutcomeStatus::bad_reply) {
        // A reply that does not fit the request is still an answer: the device is
        // there (never counted toward taking it offline); it is not retried.
        device->consecutive_timeouts = 0;
        if (const auto* response = std::get_if<protocol::Response>(&outcome.reply);
            response != nullptr && std::holds_alternative<protocol::ExceptionResponse>(*response)) {
            ++device->stats.device_exceptions;
        }
        if (!device->online) bring_online(index, *device, now);
    } else if (outcome.status == OutcomeStatus::timeout) {
        ++device->consecutive_timeouts;
        if (!device->online) {
            // A probe that failed: back off further (rule 7: a dead device must not
            // eat the line).
            device->backoff = std::min(device->backoff * 2, device->limits.backoff_max);
            device->probe_due = now + device->backoff;
        } else if (device->consecutive_timeouts >= device->limits.offline_after) {
            take_offline(index, *device, now);
        }
        if (device->online && may_retry(transaction) &&
            transaction.attempts <= device->limits.read_retries) {
            auto& stats = device->stats.by_class[class_index(transaction.priority)];
            ++stats.retries;
            enqueue(*device, std::move(transaction), now, true);
            return;
        }
        if (may_write(transaction)) {
            log_(LogLevel::warning, describe(index) + " #" + std::to_string(transaction.id) +
                                        ": write timed out, not retried (the device may have "
                                        "acted); reported as failed");
        }
    }
    complete(std::move(transaction), outcome);
}

std::optional<TimePoint> LineScheduler::next_wakeup(TimePoint now) const {
    std::optional<TimePoint> wake;
    const auto consider = [&wake](TimePoint t) {
        if (!wake || t < *wake) wake = t;
    };
    for (const auto& [index, device] : devices_) {
        if (device.queue.empty()) continue;
        if (eligible(device, now)) return now;
        consider(ready_at(device));
        for (const Entry& entry : device.queue) {
            if (entry.transaction.deadline) consider(*entry.transaction.deadline);
        }
    }
    if (wake && *wake < now) return now;
    return wake;
}

void LineScheduler::cancel_all(OutcomeStatus status, TimePoint now) {
    for (auto& [index, device] : devices_) {
        for (Entry& entry : device.queue) {
            --device.stats.by_class[class_index(entry.transaction.priority)].depth;
            reject(std::move(entry.transaction), status, now);
        }
        device.queue.clear();
    }
}

bool LineScheduler::has_device(DeviceIndex device) const noexcept { return find(device) != nullptr; }

bool LineScheduler::online(DeviceIndex device) const noexcept {
    const Device* d = find(device);
    return d != nullptr && d->online;
}

const DeviceStats* LineScheduler::stats(DeviceIndex device) const noexcept {
    const Device* d = find(device);
    return d == nullptr ? nullptr : &d->stats;
}

std::size_t LineScheduler::queued(DeviceIndex device) const noexcept {
    const Device* d = find(device);
    return d == nullptr ? 0 : d->queue.size();
}

std::size_t LineScheduler::queued() const noexcept {
    std::size_t total = 0;
    for (const auto& [index, device] : devices_) total += device.queue.size();
    return total;
}

std::optional<TimePoint> LineScheduler::probe_due(DeviceIndex device) const noexcept {
    const Device* d = find(device);
    if (d == nullptr || d->online) return std::nullopt;
    return d->probe_due;
}

}  // namespace fieldbridge::engine
