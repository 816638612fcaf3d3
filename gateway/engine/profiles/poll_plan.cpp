#include "engine/profiles/poll_plan.hpp"

#include <algorithm>
#include <tuple>
#include <utility>

#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::engine {

namespace {

[[nodiscard]] core::FunctionCode read_function(Table table) noexcept {
    switch (table) {
        case Table::coils: return protocol::fn::read_coils;
        case Table::discrete_inputs: return protocol::fn::read_discrete_inputs;
        case Table::holding: return protocol::fn::read_holding_registers;
        case Table::input: return protocol::fn::read_input_registers;
    }
    return protocol::fn::read_holding_registers;
}

[[nodiscard]] std::size_t block_limit(Table table) noexcept {
    return is_bit_table(table) ? max_block_bits : max_block_registers;
}

[[nodiscard]] std::size_t end_of(const RegisterSpan& s) noexcept {
    return std::size_t{s.address} + s.count;
}

/// The span covering @p units (ascending).
[[nodiscard]] RegisterSpan covering(const std::vector<RegisterSpan>& units) {
    const RegisterSpan& first = units.front();
    const std::size_t end = end_of(units.back());
    return RegisterSpan{first.table, first.address, static_cast<std::uint16_t>(end - first.address)};
}

/// @p units (ascending) cut where one does not start at the end of the previous.
[[nodiscard]] std::vector<std::vector<RegisterSpan>> runs_of(const std::vector<RegisterSpan>& units) {
    std::vector<std::vector<RegisterSpan>> runs;
    for (const RegisterSpan& u : units) {
        if (runs.empty() || end_of(runs.back().back()) != u.address) {
            runs.emplace_back();
        }
        runs.back().push_back(u);
    }
    return runs;
}

/// A read of @p units (ascending): covering them, filling their runs.
[[nodiscard]] PollItem item_of(std::vector<RegisterSpan> units) {
    PollItem item;
    item.payload = read_payload(covering(units));
    for (const std::vector<RegisterSpan>& run : runs_of(units)) {
        item.fills.push_back(covering(run));
    }
    item.units = std::move(units);
    return item;
}

}  // namespace

const char* to_string(PollClass poll_class) noexcept {
    switch (poll_class) {
        case PollClass::startup: return "startup";
        case PollClass::fast: return "fast";
        case PollClass::slow: return "slow";
        case PollClass::custom: return "custom";
    }
    return "unknown";
}

Payload read_payload(const RegisterSpan& span) {
    const core::FunctionCode function = read_function(span.table);
    if (is_bit_table(span.table)) {
        return ModbusPayload{protocol::ReadBitsRequest{function.value, span.address, span.count}};
    }
    return ModbusPayload{protocol::ReadRegistersRequest{function.value, span.address, span.count}};
}

std::vector<PollItem> merge_units(std::vector<PollUnit> units) {
    const auto key = [](const PollUnit& u) {
        return std::make_tuple(u.poll_class, u.period, u.motion, u.span.table, u.span.address);
    };
    std::sort(units.begin(), units.end(), [&](const PollUnit& a, const PollUnit& b) { return key(a) < key(b); });

    std::vector<PollItem> items;
    const auto flush = [&items](const PollUnit& like, std::vector<RegisterSpan>& run) {
        if (run.empty()) {
            return;
        }
        PollItem item = item_of(std::move(run));
        run.clear();
        item.poll_class = like.poll_class;
        item.period = like.period;
        item.motion = like.motion;
        items.push_back(std::move(item));
    };

    std::vector<RegisterSpan> run;
    const PollUnit* run_like = nullptr;
    const PollUnit* previous = nullptr;
    for (const PollUnit& u : units) {
        if (u.span.count == 0) {
            continue;
        }
        const bool same_group = run_like != nullptr && run_like->poll_class == u.poll_class &&
                                run_like->period == u.period && run_like->motion == u.motion &&
                                run_like->span.table == u.span.table;
        // A unit polled twice at the same period (listed twice) is polled once.
        const bool duplicate = same_group && !run.empty() && run.back() == u.span;
        if (duplicate) {
            continue;
        }
        const std::size_t gap = same_group && !run.empty() && u.span.address >= end_of(run.back())
                                    ? u.span.address - end_of(run.back())
                                    : std::size_t{0xFFFFFFFF};
        const bool reaches = gap == 0 || (previous != nullptr && gap <= std::min(previous->max_gap, u.max_gap));
        const bool fits = reaches && end_of(u.span) - run.front().address <= block_limit(u.span.table);
        if (!fits) {
            if (run_like != nullptr) {
                flush(*run_like, run);
            }
            run_like = &u;
        }
        run.push_back(u.span);
        previous = &u;
    }
    if (run_like != nullptr) {
        flush(*run_like, run);
    }
    return items;
}

PollPlan::PollPlan(std::vector<PollItem> items) : items_(std::move(items)) {
    for (PollItem& item : items_) {
        item.id = next_id_++;
    }
}

const PollItem* PollPlan::find(std::uint32_t id) const noexcept {
    const auto it = std::find_if(items_.begin(), items_.end(), [id](const PollItem& i) { return i.id == id; });
    return it != items_.end() ? &*it : nullptr;
}

PollItem PollPlan::make_item(const PollItem& like, std::vector<RegisterSpan> units) {
    PollItem item = item_of(std::move(units));
    item.id = next_id_++;
    item.poll_class = like.poll_class;
    item.period = like.period;
    item.motion = like.motion;
    return item;
}

std::vector<PollItem> PollPlan::on_block_rejected(std::uint32_t id) {
    const auto it = std::find_if(items_.begin(), items_.end(), [id](const PollItem& i) { return i.id == id; });
    if (it == items_.end()) {
        return {};
    }
    const PollItem old = std::move(*it);
    const auto at = items_.erase(it);
    if (old.units.size() < 2) {
        // One unit the device will not read even alone: a hole after all.
        rejected_.insert(rejected_.end(), old.fills.begin(), old.fills.end());
        return {};
    }
    std::vector<PollItem> split;
    if (std::vector<std::vector<RegisterSpan>> runs = runs_of(old.units); runs.size() > 1) {
        // The read bridged gaps that no unit names: one of them may be the culprit, so
        // no read bridges them again.
        for (std::vector<RegisterSpan>& run : runs) {
            split.push_back(make_item(old, std::move(run)));
        }
        items_.insert(at, split.begin(), split.end());
        return split;
    }
    // Halves at a unit boundary: a single bad register is found in log2(n) rejections.
    const auto middle = old.units.begin() + static_cast<std::ptrdiff_t>(old.units.size() / 2);
    split.push_back(make_item(old, std::vector<RegisterSpan>(old.units.begin(), middle)));
    split.push_back(make_item(old, std::vector<RegisterSpan>(middle, old.units.end())));
    items_.insert(at, split.begin(), split.end());
    return split;
}

}  // namespace fieldbridge::engine
