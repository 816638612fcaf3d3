#pragma once
/// @file register_image.hpp
/// The register image of one device: the last value of every register the gateway
/// has seen, with the time it arrived and its quality (spec §2: "every value carries
/// its time and quality"). Modbus TCP reads are served from it when every register
/// asked for is fresh enough (spec §4); MQTT subscribes to its changes.
///
/// The four Modbus tables are kept apart; each is a vector sorted by address, so a
/// read of 125 registers is one binary search and a linear walk. Bits (coils,
/// discrete inputs) are stored as 0 / 1.
///
/// Not thread-safe: a device's image lives on its line's loop thread.

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "core/register_table.hpp"
#include "engine/transaction.hpp"

namespace fieldbridge::engine {

/// The four Modbus data tables: the engine's short name for core::RegisterTable (one
/// definition, core/register_table.hpp), with its names and is_bit_table().
using Table = core::RegisterTable;
using core::is_bit_table;
using core::table_count;
using core::to_string;

enum class Quality : std::uint8_t {
    unknown,  ///< never read (an address absent from the image)
    good,     ///< as last read from (or acknowledged by) the device
    stale,    ///< the last read of it failed, or the device came back from offline
    offline,  ///< the device is offline; the value is the last one known
};

/// "unknown", "good", "stale", "offline".
[[nodiscard]] std::string_view to_string(Quality quality) noexcept;

struct RegisterEntry {
    std::uint16_t address = 0;
    std::uint16_t value = 0;
    Quality quality = Quality::unknown;
    TimePoint updated{};  ///< when the value last arrived from the device
    bool operator==(const RegisterEntry&) const = default;
};

/// What one update changed: the addresses (ascending) of @p table whose value or
/// quality changed. An update that only refreshes the time changes nothing.
struct ImageChange {
    Table table = Table::holding;
    std::vector<std::uint16_t> addresses;
    bool operator==(const ImageChange&) const = default;
};

class RegisterImage {
public:
    using SubscriptionId = std::uint64_t;
    using Listener = std::function<void(const ImageChange&)>;

    RegisterImage() = default;
    // Subscribers capture the image's address: it does not move or copy.
    RegisterImage(const RegisterImage&) = delete;
    RegisterImage& operator=(const RegisterImage&) = delete;
    RegisterImage(RegisterImage&&) = delete;
    RegisterImage& operator=(RegisterImage&&) = delete;
    ~RegisterImage() = default;

    /// Stores @p values at @p address, @p address + 1, ... with quality good and
    /// time @p now, then notifies subscribers of what changed. Values past the end of
    /// the address space (0xFFFF) are dropped. Bit tables: any non-zero value is 1.
    void update(Table table, std::uint16_t address, std::span<const std::uint16_t> values,
                TimePoint now);

    /// Marks the present registers of the span stale (a read of them failed, or a
    /// write to them was not acknowledged). Values and times are kept.
    void mark_stale(Table table, std::uint16_t address, std::uint16_t count);

    /// Offline: every register becomes `offline` and nothing is fresh. Back online:
    /// every register becomes `stale` until it is read again.
    void set_offline(bool offline);
    [[nodiscard]] bool offline() const noexcept { return offline_; }

    /// The values of @p count registers from @p address, only when the device is
    /// online and EVERY one of them is present, good, and younger than @p max_age
    /// (so a max_age of 0 never serves from the image).
    [[nodiscard]] std::optional<std::vector<std::uint16_t>> read_fresh(Table table, std::uint16_t address,
                                                                       std::uint16_t count, TimePoint now,
                                                                       Duration max_age) const;
    /// The same, into @p out (its size is the count), without allocating. False
    /// (and @p out unspecified) when not every register is fresh.
    [[nodiscard]] bool read_fresh_into(Table table, std::uint16_t address, std::span<std::uint16_t> out,
                                       TimePoint now, Duration max_age) const;

    /// The entry at @p address, whatever its quality; nullopt when never read.
    [[nodiscard]] std::optional<RegisterEntry> get(Table table, std::uint16_t address) const;
    /// The last known value at @p address, whatever its quality; nullopt when never read.
    [[nodiscard]] std::optional<std::uint16_t> value(Table table, std::uint16_t address) const;
    /// Quality::unknown when never read.
    [[nodiscard]] Quality quality(Table table, std::uint16_t address) const;
    /// Every known register of @p table, ascending by address (a view: invalidated by
    /// the next update).
    [[nodiscard]] std::span<const RegisterEntry> entries(Table table) const noexcept;
    /// A copy of entries(@p table).
    [[nodiscard]] std::vector<RegisterEntry> snapshot(Table table) const;

    /// Takes @p other's registers (values, qualities, times) and its offline state,
    /// then notifies subscribers of every register it now holds; its own
    /// subscriptions stay. For a device swapped by a reload that reads the same
    /// registers of the same device, so the cache stays warm.
    void adopt(const RegisterImage& other);

    /// Registers @p listener; it is called synchronously after every change, on the
    /// thread that changed the image. A listener may unsubscribe (itself or others)
    /// and may subscribe new listeners (they see the next change) while called. A
    /// listener that changes the image is not called back for its own change.
    [[nodiscard]] SubscriptionId subscribe(Listener listener);
    /// False when @p id is not (or no longer) subscribed.
    bool unsubscribe(SubscriptionId id);

private:
    using Slots = std::vector<RegisterEntry>;
    struct Subscriber {
        SubscriptionId id = 0;
        Listener listener;
        bool active = true;
    };

    [[nodiscard]] Slots& slots(Table table) noexcept { return tables_[static_cast<std::size_t>(table)]; }
    [[nodiscard]] const Slots& slots(Table table) const noexcept {
        return tables_[static_cast<std::size_t>(table)];
    }
    [[nodiscard]] const RegisterEntry* find(Table table, std::uint16_t address) const;
    void notify(const ImageChange& change);
    void set_quality_all(Quality quality);

    std::array<Slots, table_count> tables_{};
    bool offline_ = false;
    std::vector<Subscriber> subscribers_;
    SubscriptionId next_id_ = 1;
    unsigned notifying_ = 0;      ///< depth of notify() calls in progress
    bool prune_pending_ = false;  ///< unsubscribed while notifying: erase afterwards
};

}  // namespace fieldbridge::engine
