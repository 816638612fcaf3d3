#include "daemon/completion_barrier.hpp"

#include <stdexcept>
#include <utility>

namespace fieldbridge::daemon {

struct CompletionBarrier::State {
    struct Part {
        std::string what;
        bool done = false;
    };
    std::function<void()> on_complete;
    std::vector<Part> parts;
    std::size_t outstanding = 0;
    bool armed = false;
    bool complete = false;

    void complete_if_due() {
        if (armed && !complete && outstanding == 0) {
            complete = true;
            // Moved out first: the handler may destroy the barrier that owns us.
            auto handler = std::move(on_complete);
            if (handler) {
                handler();
            }
        }
    }
};

CompletionBarrier::Ticket::Ticket(std::weak_ptr<State> state, std::size_t index) noexcept
    : state_(std::move(state)), index_(index) {}

CompletionBarrier::Ticket::Ticket(Ticket&& other) noexcept
    : state_(std::exchange(other.state_, {})), index_(other.index_) {}

CompletionBarrier::Ticket& CompletionBarrier::Ticket::operator=(Ticket&& other) noexcept {
    if (this != &other) {
        state_ = std::exchange(other.state_, {});
        index_ = other.index_;
    }
    return *this;
}

void CompletionBarrier::Ticket::done() {
    const auto state = std::exchange(state_, {}).lock();
    if (!state) {
        return;
    }
    auto& part = state->parts.at(index_);
    if (part.done) {
        return;
    }
    part.done = true;
    --state->outstanding;
    state->complete_if_due();
}

bool CompletionBarrier::Ticket::outstanding() const noexcept {
    const auto state = state_.lock();
    return state && !state->parts[index_].done;
}

CompletionBarrier::CompletionBarrier(std::function<void()> on_complete) : state_(std::make_shared<State>()) {
    state_->on_complete = std::move(on_complete);
}

CompletionBarrier::Ticket CompletionBarrier::expect(std::string what) {
    if (state_->complete) {
        throw std::logic_error("CompletionBarrier: '" + what + "' expected after the barrier completed");
    }
    state_->parts.push_back(State::Part{std::move(what), false});
    ++state_->outstanding;
    return Ticket(state_, state_->parts.size() - 1);
}

void CompletionBarrier::arm() {
    const auto keep_alive = state_;  // the handler may destroy *this
    keep_alive->armed = true;
    keep_alive->complete_if_due();
}

bool CompletionBarrier::armed() const noexcept { return state_->armed; }

bool CompletionBarrier::complete() const noexcept { return state_->complete; }

std::vector<std::string> CompletionBarrier::pending() const {
    std::vector<std::string> names;
    for (const auto& part : state_->parts) {
        if (!part.done) {
            names.push_back(part.what);
        }
    }
    return names;
}

}  // namespace fieldbridge::daemon
