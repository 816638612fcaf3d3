#pragma once
/// @file outbox.hpp
/// Publications waiting for room with the broker (spec §6: a broker outage never
/// blocks or slows a line, so nothing here grows without bound). Bounded in messages
/// and in bytes (topic + payload). A retained message replaces the one still waiting
/// for its topic (state is a value: only the newest matters); other messages (alarm
/// events, command results, diag) wait in order. When the outbox is full the oldest
/// transient message is dropped first; a retained message (a device's current state
/// or alarm set) is only ever dropped to make room for another retained one, never
/// for a transient message (which is then dropped itself). Drops are counted. Pure.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>

#include "northbound/mqtt/mqtt_client.hpp"

namespace fieldbridge::northbound::mqtt {

class Outbox {
public:
    explicit Outbox(std::size_t capacity, std::size_t max_bytes = 4 * 1024 * 1024)
        : capacity_(capacity == 0 ? 1 : capacity), max_bytes_(max_bytes) {}

    void put(Message message);
    /// Puts @p message ahead of everything waiting (the `online` status).
    void put_first(Message message);
    [[nodiscard]] std::optional<Message> take();

    [[nodiscard]] std::size_t size() const noexcept { return queue_.size(); }
    /// Topic and payload bytes waiting.
    [[nodiscard]] std::size_t bytes() const noexcept { return bytes_; }
    [[nodiscard]] bool empty() const noexcept { return queue_.empty(); }
    /// Messages dropped because the outbox was full (or one message alone exceeded it).
    [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_; }
    /// Retained messages replaced by a newer one before they were sent.
    [[nodiscard]] std::uint64_t superseded() const noexcept { return superseded_; }
    void clear() noexcept {
        queue_.clear();
        bytes_ = 0;
    }

private:
    void drop_older_retained(const Message& message);
    /// False when @p incoming cannot be taken without dropping retained state for it.
    [[nodiscard]] bool make_room(const Message& incoming);

    std::size_t capacity_;
    std::size_t max_bytes_;
    std::size_t bytes_ = 0;
    std::deque<Message> queue_;
    std::uint64_t dropped_ = 0;
    std::uint64_t superseded_ = 0;
};

}  // namespace fieldbridge::northbound::mqtt
