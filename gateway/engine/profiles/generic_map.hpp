#pragma once
/// @file generic_map.hpp
/// The register map of a generic Modbus device (docs/registers.md, "Generic devices
/// with points"): the union of its points' registers and its raw blocks. Each point
/// is one unit of the map (a value of several registers is written whole); points
/// that share their registers exactly (the `bit:` points of one status word) share a
/// unit; the blocks' registers outside every point keep today's block pieces. A
/// register of a point follows the point: it is writable when every point on it is,
/// whatever a block says.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/point.hpp"
#include "engine/profiles/device_profile.hpp"
#include "engine/profiles/register_map.hpp"

namespace fieldbridge::engine {

/// The registers (or bits) that one or more points occupy.
struct PointUnit {
    Table table = Table::holding;
    std::uint16_t address = 0;
    std::uint16_t width = 1;
    std::vector<std::size_t> points;  ///< indices into PointModel::points, in the model's order
    [[nodiscard]] std::size_t end() const noexcept { return std::size_t{address} + width; }
};

struct GenericMap {
    std::shared_ptr<const RegisterMap> map;
    std::vector<PointUnit> units;  ///< by table, then address
};

/// Throws ProfileError (naming the block or point and the fix) for no blocks and no
/// points, a block as GenericProfile says, a point past 0xFFFF or wider than one read,
/// a `bit` above 15, a writable point of a read-only table, two points that overlap
/// without sharing the same registers, or an alarm on a point the device lacks.
[[nodiscard]] GenericMap build_generic_map(const std::vector<GenericBlock>& blocks, const core::PointModel& model);

}  // namespace fieldbridge::engine
