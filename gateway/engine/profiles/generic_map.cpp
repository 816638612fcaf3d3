#include "engine/profiles/generic_map.hpp"

#include <algorithm>
#include <set>
#include <string>
#include <tuple>
#include <utility>

#include "engine/profiles/profile_text.hpp"

namespace fieldbridge::engine {

namespace {

[[nodiscard]] std::string describe(const GenericBlock& b) {
    return std::string{to_string(b.table)} + " block at " + hex_word(b.address) + " (count " +
           std::to_string(b.count) + ")";
}

void check_block(const GenericBlock& b) {
    const std::uint16_t limit = is_bit_table(b.table) ? max_block_bits : max_block_registers;
    if (b.count == 0 || b.count > limit) {
        throw ProfileError("modbus device: " + describe(b) + ": count must be 1-" + std::to_string(limit) +
                           " (one read); split the block");
    }
    if (std::size_t{b.address} + b.count > 0x10000) {
        throw ProfileError("modbus device: " + describe(b) + " runs past address 0xFFFF; shorten it");
    }
    if (b.writable && (b.table == Table::discrete_inputs || b.table == Table::input)) {
        throw ProfileError("modbus device: " + describe(b) +
                           " is marked writable, but Modbus cannot write that table; remove `writable`");
    }
    if (b.period <= Duration::zero()) {
        throw ProfileError("modbus device: " + describe(b) + ": the poll period must be positive");
    }
}

[[nodiscard]] std::string describe(const core::PointDef& p) {
    return "point '" + p.name + "' (" + std::string{to_string(p.table)} + " " + hex_word(p.address) + ")";
}

void check_point(const core::PointDef& p) {
    const std::uint16_t width = p.width();
    if (width == 0 || width > max_unit_width) {
        throw ProfileError("modbus device: " + describe(p) + " spans " + std::to_string(width) +
                           " registers: a point must fit one read (1-125); check its `count`");
    }
    if (std::size_t{p.address} + width > 0x10000) {
        throw ProfileError("modbus device: " + describe(p) + " runs past address 0xFFFF; check its address");
    }
    if (p.bit && *p.bit > 15) {
        throw ProfileError("modbus device: " + describe(p) + ": `bit` must be 0-15");
    }
    if (p.writable && (p.table == Table::discrete_inputs || p.table == Table::input)) {
        throw ProfileError("modbus device: " + describe(p) +
                           " is marked writable, but Modbus cannot write that table; remove `writable`");
    }
    if (p.period <= std::chrono::milliseconds::zero()) {
        throw ProfileError("modbus device: " + describe(p) + ": the poll period must be positive");
    }
}

/// The points grouped into units; throws for a partial overlap.
[[nodiscard]] std::vector<PointUnit> point_units(const core::PointModel& point_model) {
    std::vector<PointUnit> units;
    for (std::size_t i = 0; i < point_model.points.size(); ++i) {
        const core::PointDef& p = point_model.points[i];
        check_point(p);
        units.push_back(PointUnit{p.table, p.address, p.width(), {i}});
    }
    std::stable_sort(units.begin(), units.end(), [](const PointUnit& a, const PointUnit& b) {
        return std::tie(a.table, a.address) < std::tie(b.table, b.address);
    });
    std::vector<PointUnit> merged;
    for (PointUnit& u : units) {
        if (!merged.empty() && merged.back().table == u.table && merged.back().end() > u.address) {
            PointUnit& last = merged.back();
            if (last.address != u.address || last.width != u.width) {
                throw ProfileError("modbus device: " + describe(point_model.points[last.points.front()]) + " and " +
                                   describe(point_model.points[u.points.front()]) +
                                   " overlap: points may share registers only exactly (the `bit:` points of "
                                   "one register); move one of them");
            }
            last.points.push_back(u.points.front());
            continue;
        }
        merged.push_back(std::move(u));
    }
    for (PointUnit& u : merged) {
        std::sort(u.points.begin(), u.points.end());
    }
    return merged;
}

[[nodiscard]] RegisterDef entry_of(const PointUnit& u, const core::PointModel& point_model) {
    RegisterDef d;
    d.table = u.table;
    d.address = u.address;
    d.width = static_cast<std::uint8_t>(u.width);
    bool writable = u.table == Table::coils || u.table == Table::holding;
    std::string names;
    for (const std::size_t i : u.points) {
        writable = writable && point_model.points[i].writable;
        names += (names.empty() ? "" : ", ") + point_model.points[i].name;
    }
    d.access = writable ? Access::read_write : Access::read;
    // The point's own checks (GenericProfile::validate) judge the value; the entry's
    // range is what the raw unit can hold.
    d.max = is_bit_table(u.table) ? 1 : (u.width == 2 ? 0xFFFFFFFF : 0xFFFF);
    d.name = (u.points.size() > 1 ? "points " : "point ") + names;
    return d;
}

/// The blocks' pieces outside every point: cut where a block or a point starts or
/// ends; a piece is writable when any block covering it is.
void add_block_pieces(const std::vector<GenericBlock>& blocks, const std::vector<PointUnit>& units,
                      std::vector<RegisterDef>& defs) {
    for (std::size_t t = 0; t < table_count; ++t) {
        const auto table = static_cast<Table>(t);
        std::set<std::size_t> cuts;
        for (const GenericBlock& b : blocks) {
            if (b.table == table) {
                cuts.insert(b.address);
                cuts.insert(std::size_t{b.address} + b.count);
            }
        }
        for (const PointUnit& u : units) {
            if (u.table == table) {
                cuts.insert(u.address);
                cuts.insert(u.end());
            }
        }
        for (auto it = cuts.begin(); it != cuts.end() && std::next(it) != cuts.end(); ++it) {
            const std::size_t from = *it;
            const std::size_t to = *std::next(it);
            const bool in_point = std::any_of(units.begin(), units.end(), [&](const PointUnit& u) {
                return u.table == table && u.address <= from && to <= u.end();
            });
            bool covered = false;
            bool writable = false;
            for (const GenericBlock& b : blocks) {
                if (b.table == table && b.address <= from && to <= std::size_t{b.address} + b.count) {
                    covered = true;
                    writable = writable || b.writable;
                }
            }
            if (!covered || in_point) {
                continue;  // a gap between blocks (a hole), or a point's own unit
            }
            RegisterDef d;
            d.table = table;
            d.address = static_cast<std::uint16_t>(from);
            d.count = static_cast<std::uint16_t>(to - from);
            d.access = writable ? Access::read_write : Access::read;
            d.max = is_bit_table(table) ? 1 : 0xFFFF;
            d.name = std::string{to_string(table)} + " " + hex_word(d.address);
            defs.push_back(std::move(d));
        }
    }
}

}  // namespace

GenericMap build_generic_map(const std::vector<GenericBlock>& blocks, const core::PointModel& point_model) {
    if (blocks.empty() && point_model.points.empty()) {
        throw ProfileError(
            "modbus device: no register blocks and no points configured; add `blocks:` with table, address, "
            "count, or `points:` (or a `type:` with a device definition)");
    }
    for (const GenericBlock& b : blocks) {
        check_block(b);
    }
    for (const core::AlarmRule& rule : point_model.alarms) {
        if (std::none_of(point_model.points.begin(), point_model.points.end(),
                         [&rule](const core::PointDef& p) { return p.name == rule.point; })) {
            throw ProfileError("modbus device: alarm '" + rule.name + "' is on point '" + rule.point +
                               "', which the device does not have; name one of its points");
        }
    }
    GenericMap out;
    out.units = point_units(point_model);
    std::vector<RegisterDef> defs;
    for (const PointUnit& u : out.units) {
        defs.push_back(entry_of(u, point_model));
    }
    add_block_pieces(blocks, out.units, defs);
    out.map = std::make_shared<const RegisterMap>(std::move(defs));
    return out;
}

}  // namespace fieldbridge::engine
