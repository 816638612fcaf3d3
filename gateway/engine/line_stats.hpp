#pragma once
/// @file line_stats.hpp
/// Counters and latency histograms of a line (read by the diag / Prometheus export).
/// Plain values: the line's loop thread owns them; exporters copy a snapshot.

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>

#include "engine/transaction.hpp"

namespace fieldbridge::engine {

/// Fixed buckets sized for serial transactions: a 2-register read at 115200 bit/s
/// takes about 3 ms, a timeout 100 ms and more.
class LatencyHistogram {
public:
    /// Upper bounds (inclusive) of the buckets; one more bucket holds the rest.
    static constexpr std::array<std::chrono::microseconds, 16> bounds{
        std::chrono::microseconds{500},     std::chrono::microseconds{1'000},
        std::chrono::microseconds{2'000},   std::chrono::microseconds{3'000},
        std::chrono::microseconds{4'000},   std::chrono::microseconds{5'000},
        std::chrono::microseconds{6'000},   std::chrono::microseconds{8'000},
        std::chrono::microseconds{10'000},  std::chrono::microseconds{15'000},
        std::chrono::microseconds{20'000},  std::chrono::microseconds{50'000},
        std::chrono::microseconds{100'000}, std::chrono::microseconds{200'000},
        std::chrono::microseconds{500'000}, std::chrono::microseconds{1'000'000}};
    static constexpr std::size_t bucket_count = bounds.size() + 1;

    void record(Duration value) noexcept;

    [[nodiscard]] std::uint64_t count() const noexcept { return count_; }
    [[nodiscard]] Duration sum() const noexcept { return sum_; }
    [[nodiscard]] Duration max() const noexcept { return max_; }
    /// Samples in bucket @p index (0 .. bucket_count-1; the last one is "above 1 s").
    [[nodiscard]] std::uint64_t bucket(std::size_t index) const noexcept { return buckets_.at(index); }
    /// The upper bound of the bucket holding the @p fraction quantile (0 < fraction <= 1):
    /// "p50 <= this". The overflow bucket answers max(). Zero when empty.
    [[nodiscard]] Duration quantile_upper_bound(double fraction) const noexcept;

private:
    std::array<std::uint64_t, bucket_count> buckets_{};
    std::uint64_t count_ = 0;
    Duration sum_{};
    Duration max_{};
};

/// Per-line counters kept by the line master.
struct LineCounters {
    std::uint64_t requests = 0;       ///< unicast requests written (every attempt)
    std::uint64_t replies = 0;        ///< valid replies (Modbus exception replies included)
    std::uint64_t timeouts = 0;       ///< attempts that ended without a valid reply
    std::uint64_t crc_errors = 0;     ///< frames dropped for a bad CRC
    std::uint64_t wrong_address = 0;  ///< runs of bytes dropped as coming from another slave
    std::uint64_t bad_replies = 0;    ///< well-framed replies that do not answer the request
    std::uint64_t garbage_bytes = 0;  ///< bytes dropped outside any recognised frame
    std::uint64_t echo_mismatch = 0;  ///< requests whose local echo differed from what was sent
    std::uint64_t broadcasts = 0;     ///< broadcasts written
    std::uint64_t expired = 0;        ///< deadlines that passed while waiting for the silence
    std::uint64_t bytes_tx = 0;
    std::uint64_t bytes_rx = 0;
    /// Time a transaction was in the master (start to finish). Utilisation % is the
    /// growth of busy_time over the wall time between two snapshots.
    Duration busy_time{};
};

}  // namespace fieldbridge::engine
