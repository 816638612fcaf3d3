#pragma once
/// @file offline_buffer.hpp
/// Data produced while no Sparkplug session can carry it (the broker is away, or the
/// primary host is not online): kept, bounded, and handed back oldest first to be
/// published after the births with `is_historical` set (docs/sparkplug-session.md,
/// "Offline buffer"). Bounded by a number of messages and by the memory they hold;
/// beyond either bound the oldest are dropped, and counted. Pure.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "northbound/sparkplug/payload.hpp"

namespace fieldbridge::northbound::sparkplug_session {

/// One DDATA (or NDATA: an empty device) as it would have been published.
struct BufferedData {
    std::string device;  ///< empty: the edge node's own metrics
    std::vector<sparkplug::Metric> metrics;
    std::uint64_t timestamp = 0;  ///< ms since the Unix epoch, UTC: when it was produced
    bool operator==(const BufferedData&) const = default;
};

/// The memory one buffered message holds, as the bound counts it: the structures
/// themselves and every string's characters.
[[nodiscard]] std::size_t buffered_bytes(const BufferedData& data) noexcept;

class OfflineBuffer {
public:
    OfflineBuffer(std::size_t max_messages, std::size_t max_bytes) noexcept
        : max_messages_(max_messages), max_bytes_(max_bytes) {}

    /// Keeps @p data, dropping the oldest until both bounds hold; a message larger
    /// than max_bytes on its own is dropped itself.
    void push(BufferedData data);
    /// Everything kept, oldest first; the buffer is empty afterwards.
    [[nodiscard]] std::vector<BufferedData> take_all();
    /// Counts a message taken out that could not be published (its device is gone).
    void count_dropped(std::uint64_t messages = 1) noexcept { dropped_ += messages; }

    [[nodiscard]] std::size_t size() const noexcept { return items_.size(); }
    [[nodiscard]] std::size_t bytes() const noexcept { return bytes_; }
    /// Messages dropped since start.
    [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_; }

private:
    struct Item {
        BufferedData data;
        std::size_t bytes = 0;
    };
    std::size_t max_messages_;
    std::size_t max_bytes_;
    std::deque<Item> items_;
    std::size_t bytes_ = 0;
    std::uint64_t dropped_ = 0;
};

}  // namespace fieldbridge::northbound::sparkplug_session
