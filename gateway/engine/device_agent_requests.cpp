// DeviceAgent: northbound requests (spec §4): answered locally, from the image, or
// through the line one payload after another, then by the profile's respond().
#include <algorithm>
#include <utility>

#include <asio/post.hpp>

#include "engine/device_agent_answers.hpp"
#include "engine/device_agent_impl.hpp"
#include "engine/profiles/register_map.hpp"

namespace fieldbridge::engine {

using protocol::ExceptionCode;

void DeviceAgent::Impl::request(const protocol::Request& request, ResponseHandler done) {
    // A line completion inside this call (a test's synchronous line, say) must still
    // not answer from inside request(): answer() posts while this is set.
    ++in_request_;
    struct Leave {
        unsigned& depth;
        ~Leave() { --depth; }
    } leave{in_request_};
    if (state_ == State::stopped) {
        // The agent is being replaced (reconfiguration, shutdown): nothing goes to
        // the line any more, as for a unit whose line is down.
        post_answer(std::move(done), exception_response(request, protocol::GatewayRefusal::path_down));
        return;
    }
    // Spec §4: what the profile knows to be invalid costs no line time.
    if (const std::optional<ExceptionCode> bad = profile_->validate(request, image_)) {
        post_answer(std::move(done), exception_response(request, *bad));
        return;
    }
    const Classification classification = profile_->classify(request);
    if (!classification.write) {
        if (auto cached = answer_from_image(request, image_, Clock::now(), config_.max_age)) {
            post_answer(std::move(done), std::move(*cached));
            return;
        }
    }
    std::vector<Payload> payloads = profile_->to_line(request, image_);
    if (payloads.empty()) {
        // Nothing the device must be asked: the profile answers from the image.
        post_answer(std::move(done), profile_->respond(request, {}, image_));
        return;
    }
    auto op = std::make_shared<Operation>();
    op->request = request;
    op->done = std::move(done);
    op->classification = classification;
    op->payloads = std::move(payloads);
    operations_.push_back(op);
    if (classification.motion) {
        // Rule 5: status at the motion period from now until the motion is over; the
        // status polls queue behind the command (commands go first).
        ++motion_commands_;
        start_motion("motion command");
    }
    submit_step(op);
}

void DeviceAgent::Impl::submit_step(const OperationPtr& op) {
    const Classification& c = op->classification;
    Transaction t = transaction(op->payloads[op->replies.size()], c.write ? Priority::command : Priority::on_demand);
    // Rule 9 for commands; for reads the same bound keeps a client from waiting on a
    // busy line forever. Each payload of a sequence gets its own deadline, so a
    // client waits at most (payloads x (command_ttl + one transaction)).
    t.deadline = Clock::now() + config_.command_ttl;
    if (c.write) {
        t.delay_before = config_.delay_before_command;  // rule 11
        t.urgent = c.urgent_stop;                       // rule 4
        t.retry_allowed = false;                        // rule 6
    } else {
        t.retry_allowed = c.idempotent;
    }
    t.on_done = [weak = weak_from_this(), op](const Outcome& outcome) {
        if (const auto self = weak.lock()) {
            self->on_step_done(op, outcome);
        }
    };
    submit_(std::move(t));
}

void DeviceAgent::Impl::on_step_done(const OperationPtr& op, const Outcome& outcome) {
    if (op->answered || op->replies.size() >= op->payloads.size()) {
        return;
    }
    const TimePoint now = outcome_time(outcome);
    if (outcome.status != OutcomeStatus::ok) {
        if (outcome.status == OutcomeStatus::timeout || outcome.status == OutcomeStatus::bad_reply) {
            // Unanswered read, or a write whose effect is unknown (the device may
            // have acted, rule 6): what it covers is no longer known to be current.
            if (const std::optional<RequestSpan> span = request_span(op->request)) {
                image_.mark_stale(span->table, span->address, span->count);
            }
        }
        answer(op, exception_response(op->request, refusal_for(outcome.status)), Delivery::now);
        return;
    }
    const Payload& sent = op->payloads[op->replies.size()];
    const ApplyResult result = profile_->apply(sent, outcome.reply, image_, now);
    op->replies.push_back(outcome.reply);
    handle_extras(result, true);
    update_motion(std::nullopt);
    if (result.status != ApplyStatus::applied || op->replies.size() == op->payloads.size()) {
        // Done, or stopped at the first payload that failed: respond() passes a
        // device exception through under the client's function code and answers
        // 0x0B for a sequence cut short.
        answer(op, profile_->respond(op->request, op->replies, image_), Delivery::now);
        return;
    }
    if (state_ == State::stopped) {
        answer(op, exception_response(op->request, refusal_for(OutcomeStatus::cancelled)), Delivery::now);
        return;
    }
    submit_step(op);
}

void DeviceAgent::Impl::broadcast_written(const protocol::Request& request) {
    if (const std::optional<RequestSpan> span = request_span(request)) {
        image_.mark_stale(span->table, span->address, span->count);
    }
    if (profile_->classify(request).motion) mark_motion_status_stale();
}

void DeviceAgent::Impl::mark_motion_status_stale() {
    for (const auto& item : polls_.plan().items()) {
        if (!item.motion) continue;
        for (const auto& span : item.fills) image_.mark_stale(span.table, span.address, span.count);
    }
}

void DeviceAgent::Impl::answer(const OperationPtr& op, protocol::Response response, Delivery delivery) {
    if (op->answered) {
        return;
    }
    op->answered = true;
    operations_.erase(std::remove(operations_.begin(), operations_.end(), op), operations_.end());
    if (op->classification.motion && motion_commands_ > 0) {
        --motion_commands_;
        motion_command_done_ = Clock::now();
    }
    if (op->classification.motion && !std::holds_alternative<protocol::ExceptionResponse>(response)) {
        // The status read before the device took the command says nothing about the
        // motion it starts: until the next motion poll refreshes it, a client's read
        // of it goes to the line (a fresh-looking "idle" right after a reset would
        // tell a PLC the homing is already done).
        mark_motion_status_stale();
    }
    if (delivery == Delivery::now && in_request_ == 0 && op->done) {
        // From the line's completion, on the loop: the agent's state is settled, and
        // the caller's next request (a TCP client's, a poll loop's) joins the line
        // worker's inbox while it still runs instead of costing another pass through
        // the reactor (docs/performance.md, "CPU per transaction").
        const ResponseHandler done = std::move(op->done);
        done(response);
        return;
    }
    post_answer(std::move(op->done), std::move(response));
}

void DeviceAgent::Impl::post_answer(ResponseHandler done, protocol::Response response) {
    if (!done) {
        return;
    }
    // Never from inside request() (the caller may hold locks or iterate), and the
    // handler does not touch the agent, so it may run after the agent is gone.
    asio::post(io_, [done = std::move(done), response = std::move(response)] { done(response); });
}

}  // namespace fieldbridge::engine
