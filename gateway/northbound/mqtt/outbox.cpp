#include "northbound/mqtt/outbox.hpp"

#include <algorithm>
#include <utility>

namespace fieldbridge::northbound::mqtt {

void Outbox::drop_older_retained(const Message& message) {
    if (!message.retained) return;
    const auto old = std::find_if(queue_.begin(), queue_.end(),
                                  [&](const Message& m) { return m.retained && m.topic == message.topic; });
    if (old != queue_.end()) {
        queue_.erase(old);
        ++superseded_;
    }
}

void Outbox::make_room() {
    while (queue_.size() >= capacity_) {
        queue_.pop_front();
        ++dropped_;
    }
}

void Outbox::put(Message message) {
    drop_older_retained(message);
    make_room();
    queue_.push_back(std::move(message));
}

void Outbox::put_first(Message message) {
    drop_older_retained(message);
    make_room();
    queue_.push_front(std::move(message));
}

std::optional<Message> Outbox::take() {
    if (queue_.empty()) return std::nullopt;
    Message m = std::move(queue_.front());
    queue_.pop_front();
    return m;
}

}  // namespace fieldbridge::northbound::mqtt
