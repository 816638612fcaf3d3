#include "engine/points/point_requests.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <tuple>

namespace fieldbridge::engine::points {

namespace {

using core::PointDef;
using core::RegisterTable;

[[nodiscard]] PointRequests refusal(std::string_view name, std::string why) {
    PointRequests r;
    r.error = "point '" + std::string{name} + "': " + std::move(why);
    r.point = std::string{name};
    return r;
}

[[nodiscard]] bool writable_table(RegisterTable t) noexcept {
    return t == RegisterTable::coils || t == RegisterTable::holding;
}

[[nodiscard]] protocol::Request write_of(const PointDef& p, const std::vector<std::uint16_t>& registers) {
    if (p.table == RegisterTable::coils) {
        return protocol::WriteSingleCoilRequest{p.address, registers.front() != 0};
    }
    if (p.bit) {
        // FC22: result = (current AND and_mask) OR (or_mask AND NOT and_mask).
        const auto bit = static_cast<std::uint16_t>(1U << *p.bit);
        return protocol::MaskWriteRegisterRequest{p.address, static_cast<std::uint16_t>(~bit & 0xFFFFU),
                                                  registers.front()};
    }
    if (registers.size() == 1) {
        return protocol::WriteSingleRegisterRequest{p.address, registers.front()};
    }
    return protocol::WriteMultipleRegistersRequest{p.address, registers};
}

struct Span {
    RegisterTable table = RegisterTable::holding;
    std::size_t address = 0;
    std::size_t end = 0;
};

[[nodiscard]] protocol::Request read_of(const Span& s) {
    const auto address = static_cast<std::uint16_t>(s.address);
    const auto count = static_cast<std::uint16_t>(s.end - s.address);
    switch (s.table) {
        case RegisterTable::coils: return protocol::ReadBitsRequest{protocol::fc::read_coils, address, count};
        case RegisterTable::discrete_inputs:
            return protocol::ReadBitsRequest{protocol::fc::read_discrete_inputs, address, count};
        case RegisterTable::input:
            return protocol::ReadRegistersRequest{protocol::fc::read_input_registers, address, count};
        case RegisterTable::holding: break;
    }
    return protocol::ReadRegistersRequest{protocol::fc::read_holding_registers, address, count};
}

}  // namespace

const PointDef* find_point(const core::PointModel& model, std::string_view name) noexcept {
    const auto it = std::find_if(model.points.begin(), model.points.end(),
                                 [name](const PointDef& p) { return p.name == name; });
    return it != model.points.end() ? &*it : nullptr;
}

PointRequests write_requests(const core::PointModel& model, std::span<const PointWrite> writes) {
    PointRequests out;
    for (const PointWrite& w : writes) {
        const PointDef* p = find_point(model, w.name);
        if (p == nullptr) {
            return refusal(w.name, "the device has no such point; its points are listed in its `fields`");
        }
        if (!p->writable || !writable_table(p->table)) {
            return refusal(w.name, "read-only; only points marked `writable` can be written");
        }
        const Encoded e = encode(*p, w.value);
        if (!e.ok()) {
            return refusal(w.name, e.error);
        }
        out.requests.push_back(write_of(*p, e.registers));
    }
    return out;
}

PointRequests read_requests(const core::PointModel& model, std::span<const std::string> names) {
    std::vector<Span> spans;
    for (const std::string& name : names) {
        const PointDef* p = find_point(model, name);
        if (p == nullptr) {
            return refusal(name, "the device has no such point; its points are listed in its `fields`");
        }
        spans.push_back(Span{p->table, p->address, std::size_t{p->address} + p->width()});
    }
    std::sort(spans.begin(), spans.end(), [](const Span& a, const Span& b) {
        return std::tie(a.table, a.address, a.end) < std::tie(b.table, b.address, b.end);
    });
    PointRequests out;
    std::vector<Span> merged;
    for (const Span& s : spans) {
        const std::size_t limit =
            core::is_bit_table(s.table) ? protocol::max_read_bits : protocol::max_read_registers;
        if (!merged.empty() && merged.back().table == s.table && s.address <= merged.back().end &&
            std::max(merged.back().end, s.end) - merged.back().address <= limit) {
            merged.back().end = std::max(merged.back().end, s.end);
            continue;
        }
        merged.push_back(s);
    }
    for (const Span& s : merged) {
        out.requests.push_back(read_of(s));
    }
    return out;
}

}  // namespace fieldbridge::engine::points
