#include "northbound/mqtt/outbox.hpp"

#include <algorithm>
#include <utility>

namespace fieldbridge::northbound::mqtt {
namespace {

[[nodiscard]] std::size_t cost(const Message& message) noexcept {
    return message.topic.size() + message.payload.size();
}

}  // namespace

void Outbox::drop_older_retained(const Message& message) {
    if (!message.retained) return;
    const auto old = std::find_if(queue_.begin(), queue_.end(),
                                  [&](const Message& m) { return m.retained && m.topic == message.topic; });
    if (old != queue_.end()) {
        bytes_ -= cost(*old);
        queue_.erase(old);
        ++superseded_;
    }
}

bool Outbox::make_room(const Message& incoming) {
    const std::size_t size = cost(incoming);
    if (size > max_bytes_) return false;
    if (!incoming.retained) {
        // Only transient messages may make room for a transient one: give up before
        // dropping any of them when that cannot be enough.
        std::size_t retained_bytes = 0;
        std::size_t retained_count = 0;
        for (const Message& m : queue_) {
            if (!m.retained) continue;
            retained_bytes += cost(m);
            ++retained_count;
        }
        if (retained_count >= capacity_ || retained_bytes + size > max_bytes_) return false;
    }
    while (queue_.size() >= capacity_ || bytes_ + size > max_bytes_) {
        auto victim = std::find_if(queue_.begin(), queue_.end(), [](const Message& m) { return !m.retained; });
        if (victim == queue_.end()) {
            if (!incoming.retained) return false;
            victim = queue_.begin();
        }
        bytes_ -= cost(*victim);
        queue_.erase(victim);
        ++dropped_;
    }
    return true;
}

void Outbox::put(Message message) {
    drop_older_retained(message);
    if (!make_room(message)) {
        ++dropped_;
        return;
    }
    bytes_ += cost(message);
    queue_.push_back(std::move(message));
}

void Outbox::put_first(Message message) {
    drop_older_retained(message);
    if (!make_room(message)) {
        ++dropped_;
        return;
    }
    bytes_ += cost(message);
    queue_.push_front(std::move(message));
}

std::optional<Message> Outbox::take() {
    if (queue_.empty()) return std::nullopt;
    Message m = std::move(queue_.front());
    queue_.pop_front();
    bytes_ -= cost(m);
    return m;
}

}  // namespace fieldbridge::northbound::mqtt
