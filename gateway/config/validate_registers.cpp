// Step 2 of loading for a built-in type's definition (docs/devices.md, "Built-in
// types"): `behaviour:` and the rows of `registers:`.
#include <algorithm>
#include <string>
#include <vector>

#include "config/validate.hpp"

namespace fieldbridge::config {

namespace {

/// The widest unit a built-in's map holds: one register or a 32-bit pair.
constexpr Range<std::int64_t> width_range{1, 2};
constexpr Range<std::int64_t> count_range{1, 0xFFFF};

struct RowSpan {
    RegisterTable table = RegisterTable::holding;
    std::int64_t first = 0;
    std::int64_t last = 0;
    std::string path;
    bool readable = true;
};

/// The value range a row of @p width can hold: 16 bits, or a 32-bit pair either
/// unsigned or two's complement.
[[nodiscard]] Range<std::int64_t> value_range(std::int64_t width) noexcept {
    return width == 2 ? Range<std::int64_t>{-0x8000'0000LL, 0xFFFF'FFFFLL} : Range<std::int64_t>{0, 0xFFFF};
}

/// Checks one row; returns its span when its table, address, width and count are valid.
std::optional<RowSpan> check_register(const RawRegister& row, DiagnosticSink& sink) {
    if (!row.ok()) {
        return std::nullopt;
    }
    if (require(sink, row.name, "the manual's name of the register, e.g. rabs") && row.name->empty()) {
        sink.error(row.name, "an empty name; expected the manual's name of the register");
    }
    const bool has_address = require(sink, row.address, "the first register, e.g. 0x0200") &&
                             check_range(sink, row.address, Range<std::int64_t>{0, 0xFFFF});
    const bool has_width = row.width.absent() || check_range(sink, row.width, width_range);
    const bool has_count = row.count.absent() || check_range(sink, row.count, count_range);
    const std::int64_t width = row.width.value_or(1);
    const std::int64_t count = row.count.value_or(1);
    require(sink, row.access, "read, write or read_write");
    const bool read_only_table = row.table.has_value() && (*row.table == RegisterTable::input ||
                                                            *row.table == RegisterTable::discrete_inputs);
    if (read_only_table && row.access.has_value() && core::can_write(*row.access)) {
        sink.error(row.access, std::string(core::to_string(*row.table)) +
                                   " cannot be written over Modbus; expected access: read");
    }
    const bool bits = row.table.has_value() && core::is_bit_table(*row.table);
    if (bits && width != 1) {
        sink.error(row.width, "a row of coils or discrete inputs is one bit wide; expected width: 1");
    }
    const Range<std::int64_t> values = bits ? Range<std::int64_t>{0, 1} : value_range(width);
    const bool min_ok = row.min.absent() || check_range(sink, row.min, values);
    const bool max_ok = row.max.absent() || check_range(sink, row.max, values);
    if (min_ok && max_ok && row.min.value_or(0) > row.max.value_or(values.max)) {
        sink.error(row.max, "max " + std::to_string(row.max.value_or(values.max)) + " is below min " +
                                std::to_string(row.min.value_or(0)) + "; expected min <= max");
    }
    if (row.stop.has_value()) {
        check_range(sink, row.stop, Range<std::int64_t>{0, 0xFFFF});
    }
    if (row.protect.value_or(false) && row.motion.value_or(false)) {
        sink.error(row.protect, "a register is either a motion command or protected, not both; remove one");
    }
    if (!has_address || !has_width || !has_count || row.table.invalid) {
        return std::nullopt;
    }
    const std::int64_t last = *row.address + width * count - 1;
    if (last > 0xFFFF) {
        sink.error(row.count, "the row runs past register 0xFFFF (to " + hex16(last) +
                                  "); expected address + width x count - 1 <= 0xFFFF");
        return std::nullopt;
    }
    return RowSpan{row.table.value_or(RegisterTable::holding), *row.address, last, row.path,
                   !row.access.has_value() || core::can_read(*row.access)};
}

/// A built-in type's points name what its hook polls: keys that say how to poll or
/// write a point are the hook's, and every register of a point is a readable row.
void check_builtin_point(const RawPoint& point, const std::vector<RowSpan>& rows, std::string_view hook,
                         DiagnosticSink& sink) {
    for (const auto& [field, key] : {std::pair{&point.min, "min"}, std::pair{&point.max, "max"}}) {
        if (field->has_value()) {
            sink.error(*field, std::string(key) + " limits writes, and a built-in type is written through its "
                                                  "registers: (min / max of the row) and its hook's ops; remove it");
        }
    }
    if (point.writable.has_value()) {
        sink.error(point.writable, "a built-in type's points are read-only (writes go through its registers: and "
                                   "the ops of its hook); remove writable");
    }
    if (point.period.has_value()) {
        sink.error(point.period, "a built-in type polls with the device's poll: periods; remove period");
    }
    if (!point.ok() || !point.table.has_value() || !point.address.has_value() || point.type.invalid ||
        point.count.invalid) {
        return;  // reported by check_points()
    }
    const core::PointType type = effective_type(point);
    const std::int64_t width = core::is_bit_table(*point.table)
                                   ? 1
                                   : core::registers_of(type, static_cast<std::uint16_t>(point.count.value_or(0)));
    for (std::int64_t address = *point.address; address < *point.address + width; ++address) {
        const auto row = std::find_if(rows.begin(), rows.end(), [&](const RowSpan& r) {
            return r.table == *point.table && r.first <= address && address <= r.last;
        });
        if (row == rows.end() || !row->readable) {
            sink.error(point.address, std::string(core::to_string(*point.table)) + " " + hex16(address) +
                                          (row == rows.end() ? " is in no row of registers:" : " is write-only in " + row->path) +
                                          "; a point of " + std::string(hook) +
                                          " decodes what its hook polls: expected a readable row there");
            return;
        }
    }
}

}  // namespace

void check_registers(const RawDefinition& definition, DiagnosticSink& sink) {
    const auto& rows = definition.registers;
    if (definition.behaviour.invalid) {
        return;  // reported: not a known hook
    }
    if (!definition.behaviour.has_value()) {
        if (rows.ok() || rows.state == RawNode::State::invalid) {
            sink.error(rows, "registers: describe a built-in type's map for its behaviour hook; a definition "
                             "without behaviour: is a generic device: use points: (or blocks:) instead");
        }
        return;
    }
    const std::string hook(core::to_string(*definition.behaviour));
    for (const RawNode* generic : std::initializer_list<const RawNode*>{&definition.blocks, &definition.identify}) {
        if (!generic->absent()) {
            sink.error(*generic, "a definition with behaviour: " + hook +
                                     " describes its registers:; what it polls and how scan finds it are its "
                                     "hook's: remove this key (blocks and identify are for generic devices)");
        }
    }
    if (!definition.max_gap.absent()) {
        sink.error(definition.max_gap, "max_gap is for points; a built-in type polls what its hook says: remove it");
    }
    if (!definition.word_order.absent()) {
        sink.error(definition.word_order, "word_order is set on the device (excd203mb), not in a built-in type's "
                                          "definition: remove it");
    }
    if (!definition.period.absent()) {
        sink.error(definition.period, "a built-in type polls with the device's poll: periods: remove period");
    }
    if (!rows.ok() || rows.items.empty()) {
        if (rows.state != RawNode::State::invalid) {
            sink.error(rows, "a definition with behaviour: needs its registers:; expected e.g. registers: "
                             "[{name: rabs, address: 0x0201, width: 2, access: read}]");
        }
        return;
    }
    std::vector<RowSpan> spans;
    for (const RawRegister& row : rows.items) {
        const auto span = check_register(row, sink);
        if (!span) {
            continue;
        }
        const auto overlap = std::find_if(spans.begin(), spans.end(), [&span](const RowSpan& other) {
            return other.table == span->table && other.first <= span->last && span->first <= other.last;
        });
        if (overlap != spans.end()) {
            sink.error(row, "registers " + hex16(span->first) + ".." + hex16(span->last) + " overlap " +
                                overlap->path + " (" + hex16(overlap->first) + ".." + hex16(overlap->last) +
                                "); expected each register in one row");
            continue;
        }
        spans.push_back(*span);
    }
    for (const RawPoint& point : definition.points.items) {
        check_builtin_point(point, spans, hook, sink);
    }
}

}  // namespace fieldbridge::config
