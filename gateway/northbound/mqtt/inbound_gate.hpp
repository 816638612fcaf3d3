#pragma once
/// @file inbound_gate.hpp
/// Bounds the messages received from the broker and not yet handled on the loop
/// (docs/mqtt.md, "Bounds"): at most `max_messages` and `max_bytes` wait at once;
/// a message beyond either is dropped and counted. Messages are admitted on the MQTT
/// library's thread and released on the loop thread, so the counts are guarded.
#include <cstddef>
#include <cstdint>
#include <mutex>

namespace fieldbridge::northbound::mqtt {

class InboundGate {
public:
    InboundGate(std::size_t max_messages, std::size_t max_bytes) noexcept
        : max_messages_(max_messages), max_bytes_(max_bytes) {}

    /// Any thread: true when a message of @p bytes may be queued (it then counts
    /// until release()); false when it must be dropped (counted).
    [[nodiscard]] bool admit(std::size_t bytes) noexcept;
    /// A message admitted with @p bytes was handled.
    void release(std::size_t bytes) noexcept;
    /// Drops since the last call: for a log line at most once per interval.
    [[nodiscard]] std::uint64_t take_unreported() noexcept;
    [[nodiscard]] std::uint64_t dropped() const noexcept;

private:
    mutable std::mutex mutex_;
    std::size_t max_messages_;
    std::size_t max_bytes_;
    std::size_t messages_ = 0;
    std::size_t bytes_ = 0;
    std::uint64_t dropped_ = 0;
    std::uint64_t reported_ = 0;
};

}  // namespace fieldbridge::northbound::mqtt
