#pragma once
/// @file outbox.hpp
/// Publications waiting for room with the broker (spec §6: a broker outage never
/// blocks or slows a line, so nothing here grows without bound). A retained message
/// replaces the one still waiting for its topic (state is a value: only the newest
/// matters); other messages (alarm events, command results, diag) wait in order, and
/// when the outbox is full the oldest waiting message is dropped and counted. Pure.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>

#include "northbound/mqtt/mqtt_client.hpp"

namespace fieldbridge::northbound::mqtt {

class Outbox {
public:
    explicit Outbox(std::size_t capacity) : capacity_(capacity == 0 ? 1 : capacity) {}

    void put(Message message);
    /// Puts @p message ahead of everything waiting (the `online` status).
    void put_first(Message message);
    [[nodiscard]] std::optional<Message> take();

    [[nodiscard]] std::size_t size() const noexcept { return queue_.size(); }
    [[nodiscard]] bool empty() const noexcept { return queue_.empty(); }
    /// Messages dropped because the outbox was full.
    [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_; }
    /// Retained messages replaced by a newer one before they were sent.
    [[nodiscard]] std::uint64_t superseded() const noexcept { return superseded_; }
    void clear() noexcept { queue_.clear(); }

private:
    void drop_older_retained(const Message& message);
    void make_room();

    std::size_t capacity_;
    std::deque<Message> queue_;
    std::uint64_t dropped_ = 0;
    std::uint64_t superseded_ = 0;
};

}  // namespace fieldbridge::northbound::mqtt
