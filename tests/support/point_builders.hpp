#pragma once
/// @file point_builders.hpp
/// The point of a test: a PointDef with its name, table, address, type and whether it
/// is writable; everything else as PointDef's defaults (set more on the result).
#include <cstdint>
#include <string>
#include <utility>

#include "core/point.hpp"

namespace fieldbridge::test {

[[nodiscard]] inline core::PointDef point_def(std::string name, core::RegisterTable table, std::uint16_t address,
                                              core::PointType type, bool writable = false) {
    core::PointDef p;
    p.name = std::move(name);
    p.table = table;
    p.address = address;
    p.type = type;
    p.writable = writable;
    return p;
}

}  // namespace fieldbridge::test
