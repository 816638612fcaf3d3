// DeviceAgent: the poll timer, poll submissions and what their replies do (spec §3
// rules 3, 5, 8). When an item is due is PollSchedule's business.
#include <string>
#include <utility>

#include "engine/device_agent_impl.hpp"
#include "engine/profiles/profile_text.hpp"

namespace fieldbridge::engine {

namespace {

/// "holding 0x0300-0x0301".
[[nodiscard]] std::string describe(const RegisterSpan& span) {
    std::string out = std::string{to_string(span.table)} + " " + hex_word(span.address);
    if (span.count > 1) {
        out += "-" + hex_word(static_cast<std::uint16_t>(span.address + span.count - 1));
    }
    return out;
}

[[nodiscard]] std::string describe(const PollItem& item) {
    if (item.fills.empty()) {
        return std::string{"a "} + to_string(item.poll_class) + " item";
    }
    std::string out;
    for (const RegisterSpan& span : item.fills) {
        out += (out.empty() ? "" : ", ") + describe(span);
    }
    return out;
}

}  // namespace

void DeviceAgent::Impl::arm_poll_timer() {
    if (state_ != State::running || !config_.polling) {
        return;
    }
    const std::optional<TimePoint> due = polls_.next_due();
    if (due == armed_for_) {
        return;  // already waiting for exactly this (or for nothing)
    }
    armed_for_ = due;
    if (!due) {
        poll_timer_.cancel();
        return;
    }
    // expires_at() cancels the wait in progress; its handler sees operation_aborted.
    poll_timer_.expires_at(*due);
    poll_timer_.async_wait([weak = weak_from_this()](const std::error_code& error) {
        if (error) {
            return;
        }
        if (const auto self = weak.lock()) {
            self->on_poll_timer();
        }
    });
}

void DeviceAgent::Impl::on_poll_timer() {
    armed_for_.reset();
    submit_due_polls();
    arm_poll_timer();
}

void DeviceAgent::Impl::submit_due_polls() {
    if (state_ != State::running) {
        return;
    }
    // Everything due now goes together, so items of one period stay side by side in
    // the line's queue. A submit may complete at once (and even split the plan), so
    // each id is looked up again.
    for (const std::uint32_t id : polls_.take_due(Clock::now())) {
        const PollItem* item = polls_.find(id);
        if (item == nullptr) {
            continue;
        }
        Transaction t = transaction(item->payload, Priority::poll);
        t.retry_allowed = true;  // polls are reads (rule 6)
        if (const Duration period = polls_.period_of(*item); period > Duration{}) {
            t.poll_period = period;  // rule 3: aged up after a period
        }
        t.on_done = [weak = weak_from_this(), id](const Outcome& outcome) {
            if (const auto self = weak.lock()) {
                self->on_poll_done(id, outcome);
            }
        };
        submit_(std::move(t));
    }
}

void DeviceAgent::Impl::on_poll_done(std::uint32_t id, const Outcome& outcome) {
    const PollItem* item = polls_.find(id);
    if (item == nullptr) {
        return;
    }
    const TimePoint now = outcome_time(outcome);
    const bool motion_item = item->motion;
    const std::vector<RegisterSpan> fills = item->fills;
    const auto mark_stale = [this, &fills] {
        for (const RegisterSpan& span : fills) {
            image_.mark_stale(span.table, span.address, span.count);
        }
    };

    if (outcome.status != OutcomeStatus::ok) {
        // A read that timed out leaves its registers stale (not fresh for reads, and
        // MQTT says so). Other failures never reached the device: queue full, line
        // down or the device offline (the image says offline already), cancelled.
        if (outcome.status == OutcomeStatus::timeout || outcome.status == OutcomeStatus::bad_reply) {
            mark_stale();
        }
        if (log_.enabled(LogLevel::debug)) {
            log(LogLevel::debug, who() + ": poll of " + describe(*item) + ": " + to_string(outcome.status));
        }
        polls_.finished(id, false, now);
        arm_poll_timer();
        return;
    }

    const ApplyResult result = profile_->apply(item->payload, outcome.reply, image_, now);
    bool answered = false;
    switch (result.status) {
        case ApplyStatus::applied:
            answered = true;
            warned_items_.erase(id);
            break;
        case ApplyStatus::device_exception:
            if (result.exception == protocol::ExceptionCode::illegal_data_address) {
                polls_.finished(id, false, now);
                on_block_rejected(id, now);
                handle_extras(result, true);
                arm_poll_timer();
                return;
            }
            // The device answered: a startup item is done, a periodic one goes on at
            // its period (profiles mark a refused read stale).
            answered = true;
            warn_poll_once(id, "was answered with exception " +
                                   hex_byte(static_cast<std::uint8_t>(result.exception.value_or(
                                       protocol::ExceptionCode::server_device_failure))));
            break;
        case ApplyStatus::not_applicable:
            mark_stale();
            warn_poll_once(id, "got a reply that does not answer it");
            break;
    }
    polls_.finished(id, answered, now);
    handle_extras(result, true);
    update_motion(motion_item && result.status == ApplyStatus::applied ? std::optional<std::uint32_t>{id}
                                                                       : std::nullopt);
    arm_poll_timer();
}

void DeviceAgent::Impl::on_block_rejected(std::uint32_t id, TimePoint now) {
    const PollItem* item = polls_.find(id);
    if (item == nullptr) {
        return;
    }
    const std::string old = describe(*item);
    const std::vector<PollItem> split = polls_.reject(id, now);
    warned_items_.erase(id);
    // Each split happens once and is remembered by the plan, so this is logged once.
    if (split.empty()) {
        log(LogLevel::warning, who() + " refused to read " + old +
                                   " even alone (exception 0x02): it is not polled any more; check the "
                                   "device's register map, or the blocks and points configured for it");
        return;
    }
    std::string halves;
    for (const PollItem& part : split) {
        halves += (halves.empty() ? "" : " and ") + describe(part);
    }
    log(LogLevel::warning, who() + " answered the block read of " + old +
                               " with exception 0x02 (illegal data address): polling it as " + halves +
                               " from now on");
}

void DeviceAgent::Impl::warn_poll_once(std::uint32_t id, std::string_view what) {
    if (!warned_items_.insert(id).second) {
        return;
    }
    const PollItem* item = polls_.find(id);
    log(LogLevel::warning, who() + ": the poll of " + (item != nullptr ? describe(*item) : std::string{"an item"}) +
                               " " + std::string{what} + " (said once until it is answered again)");
}

void DeviceAgent::Impl::update_motion(std::optional<std::uint32_t> motion_poll) {
    if (profile_->in_motion(image_)) {
        if (!polls_.motion()) {
            start_motion("the device reports motion");
        }
        return;
    }
    if (!polls_.motion() || !motion_poll || motion_commands_ > 0) {
        return;
    }
    // Only a poll sent after the last motion command finished tells the device is at
    // rest: an earlier one may show the state from before the command.
    const std::optional<TimePoint> taken = polls_.last_taken(*motion_poll);
    if (taken && *taken >= motion_command_done_) {
        polls_.set_motion(false);
        if (log_.enabled(LogLevel::debug)) {
            log(LogLevel::debug, who() + ": motion ended; status polls back to their periods");
        }
    }
}

void DeviceAgent::Impl::start_motion(std::string_view why) {
    if (!polls_.motion() && log_.enabled(LogLevel::debug)) {
        log(LogLevel::debug, who() + ": " + std::string{why} + "; polling status at the motion period");
    }
    polls_.set_motion(true);
    arm_poll_timer();
}

}  // namespace fieldbridge::engine
