#pragma once
/// @file point_def.hpp
/// A point of the point model (core/point.hpp) with the four fields every test sets;
/// the test sets the others on the result.
#include <cstdint>
#include <string>
#include <utility>

#include "core/point.hpp"

namespace fieldbridge::test {

inline core::PointDef point(std::string name, core::RegisterTable table, std::uint16_t address, core::PointType type) {
    core::PointDef p;
    p.name = std::move(name);
    p.table = table;
    p.address = address;
    p.type = type;
    return p;
}

}  // namespace fieldbridge::test
