#include "engine/profiles/register_map.hpp"

#include "core/error.hpp"
#include "engine/profiles/device_profile.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>

namespace fieldbridge::engine {

Table table_of_read(core::FunctionCode function) noexcept {
    if (function == protocol::fn::read_coils) return Table::coils;
    if (function == protocol::fn::read_discrete_inputs) return Table::discrete_inputs;
    if (function == protocol::fn::read_input_registers) return Table::input;
    return Table::holding;
}

std::optional<RequestSpan> request_span(const protocol::Request& request) {
    return std::visit(
        [](const auto& r) -> std::optional<RequestSpan> {
            using T = std::decay_t<decltype(r)>;
            if constexpr (std::is_same_v<T, protocol::ReadBitsRequest> ||
                          std::is_same_v<T, protocol::ReadRegistersRequest>) {
                return RequestSpan{table_of_read(protocol::function_code(r)), r.address, r.count, false, {}};
            } else if constexpr (std::is_same_v<T, protocol::WriteSingleCoilRequest>) {
                return RequestSpan{Table::coils, r.address, 1, true, {static_cast<std::uint16_t>(r.value ? 1 : 0)}};
            } else if constexpr (std::is_same_v<T, protocol::WriteSingleRegisterRequest>) {
                return RequestSpan{Table::holding, r.address, 1, true, {r.value}};
            } else if constexpr (std::is_same_v<T, protocol::WriteMultipleCoilsRequest>) {
                RequestSpan s{Table::coils, r.address, static_cast<std::uint16_t>(r.values.size()), true, {}};
                s.values.reserve(r.values.size());
                for (const bool b : r.values) {
                    s.values.push_back(static_cast<std::uint16_t>(b ? 1 : 0));
                }
                return s;
            } else if constexpr (std::is_same_v<T, protocol::WriteMultipleRegistersRequest>) {
                return RequestSpan{Table::holding, r.address, static_cast<std::uint16_t>(r.values.size()), true,
                                   r.values};
            } else if constexpr (std::is_same_v<T, protocol::MaskWriteRegisterRequest>) {
                // The value written depends on what the register holds: none is known.
                return RequestSpan{Table::holding, r.address, 1, true, {}};
            } else if constexpr (std::is_same_v<T, protocol::ReadWriteRegistersRequest>) {
                // FC17 writes before it reads: the write is its span (validate_request() checks the read).
                return RequestSpan{Table::holding, r.write_address, static_cast<std::uint16_t>(r.values.size()), true,
                                   r.values};
            } else {
                return std::nullopt;  // FC07, opaque (FC11 report server ID...): no span
            }
        },
        request);
}

RegisterMap::RegisterMap(std::vector<RegisterDef> defs) {
    for (RegisterDef& d : defs) {
        if (d.width < 1 || d.width > max_unit_width || d.count == 0 || d.end() > 0x10000) {
            throw core::InvalidArgument("register map entry '" + d.name + "' at " + std::to_string(d.address) +
                                        ": width must be 1-125, count at least 1, and it must end by 0xFFFF");
        }
        tables_[static_cast<std::size_t>(d.table)].push_back(std::move(d));
    }
    for (auto& table : tables_) {
        std::sort(table.begin(), table.end(),
                  [](const RegisterDef& a, const RegisterDef& b) { return a.address < b.address; });
        for (std::size_t i = 1; i < table.size(); ++i) {
            if (table[i - 1].end() > table[i].address) {
                throw core::InvalidArgument("register map entries '" + table[i - 1].name + "' and '" +
                                            table[i].name + "' overlap at " + std::to_string(table[i].address));
            }
        }
    }
}

const RegisterDef* RegisterMap::find(Table table, std::uint16_t address) const noexcept {
    const auto& defs = entries(table);
    // The last entry starting at or before address.
    auto it = std::upper_bound(defs.begin(), defs.end(), address,
                               [](std::uint16_t a, const RegisterDef& d) { return a < d.address; });
    if (it == defs.begin()) {
        return nullptr;
    }
    --it;
    return address < it->end() ? &*it : nullptr;
}

std::optional<protocol::ExceptionCode> RegisterMap::check(Table table, std::uint16_t address, std::uint16_t count,
                                                          bool write) const {
    const std::size_t end = std::size_t{address} + count;
    if (count == 0 || end > 0x10000) {
        return protocol::ExceptionCode::illegal_data_address;
    }
    std::size_t a = address;
    while (a < end) {
        const RegisterDef* d = find(table, static_cast<std::uint16_t>(a));
        if (d == nullptr || (write ? !can_write(d->access) : !can_read(d->access))) {
            return protocol::ExceptionCode::illegal_data_address;
        }
        if (write && d->width > 1) {
            // The manual's pairs (spec §5, EXCD203MB) and a generic device's points of
            // several registers must be written whole.
            if ((a - d->address) % d->width != 0 && a == address) {
                return protocol::ExceptionCode::illegal_data_address;
            }
            if (end < d->end() && (end - d->address) % d->width != 0) {
                return protocol::ExceptionCode::illegal_data_address;
            }
        }
        a = d->end();  // the whole entry is addressable: skip to its end
    }
    return std::nullopt;
}

std::vector<UnitRef> RegisterMap::units(Table table, std::uint16_t address, std::uint16_t count) const {
    std::vector<UnitRef> out;
    const std::size_t end = std::size_t{address} + count;
    std::size_t a = address;
    while (a < end && a < 0x10000) {
        const RegisterDef* d = find(table, static_cast<std::uint16_t>(a));
        if (d == nullptr) {
            ++a;
            continue;
        }
        const std::size_t unit = d->address + (a - d->address) / d->width * d->width;
        out.push_back(UnitRef{d, static_cast<std::uint16_t>(unit)});
        a = unit + d->width;
    }
    return out;
}

std::vector<PollUnit> RegisterMap::poll_units(const RegisterSpan& span, PollClass poll_class, Duration period,
                                              bool motion) const {
    std::vector<PollUnit> out;
    for (const UnitRef& u : units(span.table, span.address, span.count)) {
        out.push_back(PollUnit{RegisterSpan{span.table, u.address, u.def->width}, poll_class, period, motion, 0});
    }
    return out;
}

std::vector<WrittenUnit> written_units(const RegisterMap& map, const RequestSpan& span) {
    std::vector<WrittenUnit> out;
    for (const UnitRef& u : map.units(span.table, span.address, span.count)) {
        const std::size_t i = u.address - span.address;  // validated: units start inside the span
        if (u.address < span.address || i + u.def->width > span.values.size()) {
            continue;  // half a pair at an edge: not a whole written value
        }
        // Wider units (points of a generic device): the first register; the profile
        // checks the whole value (GenericProfile).
        const std::int64_t value = u.def->width == 2 ? pair_value(span.values[i], span.values[i + 1], u.def->is_signed)
                                                     : std::int64_t{span.values[i]};
        out.push_back(WrittenUnit{u.def, u.address, value});
    }
    return out;
}

std::optional<protocol::ExceptionCode> validate_request(const RegisterMap& map, const protocol::Request& request,
                                                        std::span<const core::FunctionCode> functions,
                                                        bool allow_protected, const ValueCheck& extra) {
    const core::FunctionCode function = protocol::function_code(request);
    if (std::find(functions.begin(), functions.end(), function) == functions.end()) {
        return protocol::ExceptionCode::illegal_function;
    }
    if (const auto* opaque = std::get_if<protocol::OpaqueRequest>(&request)) {
        // FC11 report server ID carries no data (Modbus Application Protocol 6.13);
        // other opaque codes are the profile's to list and the device's to judge.
        const bool bad_length = function == protocol::fn::report_server_id && !opaque->data.empty();
        return bad_length ? std::optional{protocol::ExceptionCode::illegal_data_value} : std::nullopt;
    }
    if (const auto* rw = std::get_if<protocol::ReadWriteRegistersRequest>(&request)) {
        // FC17's read: the same rules as an FC03 of it.
        if (const auto bad = map.check(Table::holding, rw->read_address, rw->read_count, false)) {
            return bad;
        }
    }
    const std::optional<RequestSpan> span = request_span(request);
    if (!span) {
        return std::nullopt;  // FC07: listed, no data
    }
    // Modbus Application Protocol V1.1b3 §6: quantity out of range is 0x03.
    const std::uint16_t limit = span->write ? (is_bit_table(span->table) ? protocol::max_write_coils
                                                                          : protocol::max_write_registers)
                                            : (is_bit_table(span->table) ? protocol::max_read_bits
                                                                          : protocol::max_read_registers);
    if (span->count == 0 || span->count > limit) {
        return protocol::ExceptionCode::illegal_data_value;
    }
    if (const auto bad = map.check(span->table, span->address, span->count, span->write)) {
        return bad;
    }
    if (!span->write) {
        return std::nullopt;
    }
    if (std::holds_alternative<protocol::MaskWriteRegisterRequest>(request)) {
        // FC16: the value it leaves depends on the register's current value, so only
        // a plain 16-bit register that takes any value may be masked: not half of a
        // 32-bit pair, not one with a range, a stop value or an auto reset; a
        // protected one only with allow_protected, as every other write.
        const RegisterDef* def = map.find(Table::holding, span->address);
        if (def != nullptr && def->protect && !allow_protected) {
            return protocol::ExceptionCode::illegal_function;
        }
        if (def == nullptr || def->width != 1 || def->min > 0 || def->max < 0xFFFF || def->stop_value ||
            def->auto_reset) {
            return protocol::ExceptionCode::illegal_data_value;
        }
        return std::nullopt;
    }
    const std::vector<WrittenUnit> units = written_units(map, *span);
    if (!allow_protected) {
        for (const WrittenUnit& u : units) {
            if (u.def->protect) {
                return protocol::ExceptionCode::illegal_function;
            }
        }
    }
    for (const WrittenUnit& u : units) {
        if (u.value < u.def->min || u.value > u.def->max) {
            return protocol::ExceptionCode::illegal_data_value;
        }
        if (extra) {
            if (const auto bad = extra(*u.def, u.address, u.value)) {
                return bad;
            }
        }
    }
    return std::nullopt;
}

Classification classify_request(const RegisterMap& map, const protocol::Request& request) {
    Classification c;
    c.write = protocol::is_write(protocol::function_code(request));
    c.idempotent = !c.write;
    const std::optional<RequestSpan> span = request_span(request);
    if (!c.write || !span) {
        return c;
    }
    for (const WrittenUnit& u : written_units(map, *span)) {
        c.motion = c.motion || u.def->motion;
        c.protected_write = c.protected_write || u.def->protect;
        c.urgent_stop = c.urgent_stop || (u.def->stop_value && u.value == *u.def->stop_value);
    }
    return c;
}

}  // namespace fieldbridge::engine
