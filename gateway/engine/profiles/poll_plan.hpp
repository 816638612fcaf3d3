#pragma once
/// @file poll_plan.hpp
/// What a device agent polls, how often, and what each poll fills in the image.
/// Spec §3 rule 8: adjacent registers polled at the same period are merged into one
/// block read within the device's known map, never across a hole (except the gaps of
/// at most `max_gap` registers between a generic device's points, issue 25); a merged
/// block the device answers with exception 0x02 is split, and the split is remembered
/// (the plan keeps the split items from then on; a gap is never bridged again).

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "engine/register_image.hpp"
#include "engine/transaction.hpp"

namespace fieldbridge::engine {

/// When an item is polled.
enum class PollClass : std::uint8_t {
    startup,  ///< once when the device (re)appears: model, firmware, constants
    fast,     ///< status: the `fast` period
    slow,     ///< I/O and parameters: the `slow` period
    custom,   ///< its own period (generic Modbus blocks)
};

/// "startup", "fast", "slow", "custom".
[[nodiscard]] const char* to_string(PollClass poll_class) noexcept;

/// @p count registers (or bits) of one table from @p address.
struct RegisterSpan {
    Table table = Table::holding;
    std::uint16_t address = 0;
    std::uint16_t count = 0;
    bool operator==(const RegisterSpan&) const = default;
};

struct PollItem {
    std::uint32_t id = 0;  ///< unique within its plan; assigned by the plan
    Payload payload;
    PollClass poll_class = PollClass::fast;
    Duration period{};     ///< 0 for startup items
    /// Rule 5: while the device is in motion this item is polled at the `motion`
    /// period instead (it carries what in_motion() looks at).
    bool motion = false;
    /// Image registers a good reply refreshes: the runs of adjacent units (a gap the
    /// read bridges is not a register of the device's map and is not stored).
    std::vector<RegisterSpan> fills;
    /// Modbus items: the map entries (single registers, 32-bit pairs, points, or bits)
    /// the block was merged from, ascending; adjacent unless the block bridges gaps
    /// (PollUnit::max_gap). A block of two or more units can be split; ASCII items
    /// have none.
    std::vector<RegisterSpan> units;
};

/// Limits of one block read (Modbus Application Protocol V1.1b3 §6.1-6.4).
inline constexpr std::uint16_t max_block_registers = 125;
inline constexpr std::uint16_t max_block_bits = 2000;

/// A request for one poll before merging: read @p span at @p poll_class / @p period.
struct PollUnit {
    RegisterSpan span;
    PollClass poll_class = PollClass::fast;
    Duration period{};
    bool motion = false;
    /// Registers (bits) between this unit and a neighbour that a merged read may
    /// bridge, when both allow it (the smaller wins): 0 (only touching units merge)
    /// but for a generic device's points (`max_gap`).
    std::uint16_t max_gap = 0;
};

/// The FC01/02/03/04 read of @p span.
[[nodiscard]] Payload read_payload(const RegisterSpan& span);

/// Rule 8's merge: units of one table with the same class, period and motion flag
/// whose spans touch (the next starts where the previous ends) become one block, up
/// to 125 registers / 2000 bits. Units that do not touch are bridged only across a
/// gap both allow (PollUnit::max_gap): any other gap may be a hole the device
/// rejects. Items come out ordered by class, then table, then address; ids are not
/// assigned yet.
[[nodiscard]] std::vector<PollItem> merge_units(std::vector<PollUnit> units);

class PollPlan {
public:
    PollPlan() = default;
    /// Takes the items and numbers them 1, 2, ...
    explicit PollPlan(std::vector<PollItem> items);

    [[nodiscard]] std::span<const PollItem> items() const& noexcept { return items_; }
    /// A view into a temporary plan would dangle: keep the plan in a variable.
    std::span<const PollItem> items() const&& = delete;
    [[nodiscard]] const PollItem* find(std::uint32_t id) const noexcept;

    /// The device answered item @p id with exception 0x02 (illegal data address).
    /// A block that bridges gaps is replaced by its runs of adjacent units (the gap
    /// may be the culprit: it is never read again); a block of adjacent units by two
    /// halves (split at a unit boundary, so a 32-bit pair or a point is never cut).
    /// The new items are returned with fresh ids; one that is rejected again is split
    /// again, down to single units. A single unit that is
    /// rejected is dropped from the plan and listed in rejected(). Returns the items
    /// that replace @p id (empty when it was dropped or is unknown).
    std::vector<PollItem> on_block_rejected(std::uint32_t id);

    /// Units the device refused to answer even alone; never polled again.
    [[nodiscard]] std::span<const RegisterSpan> rejected() const& noexcept { return rejected_; }
    std::span<const RegisterSpan> rejected() const&& = delete;

private:
    [[nodiscard]] PollItem make_item(const PollItem& like, std::vector<RegisterSpan> units);

    std::vector<PollItem> items_;
    std::vector<RegisterSpan> rejected_;
    std::uint32_t next_id_ = 1;
};

}  // namespace fieldbridge::engine
