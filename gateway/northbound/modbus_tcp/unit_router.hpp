#pragma once
/// @file unit_router.hpp
/// The routing table of the Modbus TCP server: unit ID -> the UnitTarget that
/// answers it. A unit without a route is answered locally with exception 0x0A
/// (gateway path unavailable, spec section 4).
///
/// The table does not own its targets: the daemon builds them (device adapters,
/// broadcast units, upstream units) and must remove a target's routes before
/// destroying it. Loop thread only.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/modbus_ids.hpp"
#include "northbound/unit_target.hpp"

namespace fieldbridge::northbound::modbus_tcp {

class UnitRouter {
public:
    /// Routes @p unit to @p target (replacing any previous route of that unit).
    void set(core::UnitId unit, UnitTarget& target) noexcept { targets_[unit.value] = &target; }
    void remove(core::UnitId unit) noexcept { targets_[unit.value] = nullptr; }
    void clear() noexcept { targets_.fill(nullptr); }

    /// nullptr when the unit has no route.
    [[nodiscard]] UnitTarget* find(core::UnitId unit) const noexcept { return targets_[unit.value]; }
    /// Units with a route.
    [[nodiscard]] std::size_t size() const noexcept;
    /// Every routed target once (a target may serve several units), in unit order.
    [[nodiscard]] std::vector<UnitTarget*> targets() const;

private:
    std::array<UnitTarget*, 256> targets_{};
};

}  // namespace fieldbridge::northbound::modbus_tcp
