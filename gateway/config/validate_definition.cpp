// Step 2 of loading for a device definition file on its own (docs/devices.md).
#include <algorithm>

#include "config/validate.hpp"

namespace fieldbridge::config {

namespace {

void check_identify(const RawIdentify& identify, DiagnosticSink& sink) {
    if (!identify.ok()) {
        return;
    }
    if (require(sink, identify.table, "holding or input") && *identify.table != RegisterTable::holding &&
        *identify.table != RegisterTable::input) {
        sink.error(identify.table, "scan identifies with a register read; expected holding or input");
    }
    const bool has_address = require(sink, identify.address, "the first register to read, e.g. 0x0000") &&
                             check_range(sink, identify.address, Range<std::int64_t>{0, 0xFFFF});
    const bool has_count =
        identify.count.absent() || check_range(sink, identify.count, Range<std::int64_t>{1, RegisterBlock::max_registers});
    const std::int64_t count = identify.count.value_or(1);
    if (has_address && has_count && *identify.address + count - 1 > 0xFFFF) {
        sink.error(identify.count, "the read runs past register 0xFFFF; expected address + count - 1 <= 0xFFFF");
    }
    for (const auto& value : identify.expect.items) {
        check_range(sink, value, Range<std::int64_t>{0, 0xFFFF});
    }
    if (!identify.expect.items.empty() && has_count &&
        static_cast<std::int64_t>(identify.expect.items.size()) != count) {
        sink.error(identify.expect, std::to_string(identify.expect.items.size()) + " values for a read of " +
                                        std::to_string(count) + " register(s); expected one value per register "
                                        "(set count)");
    }
}

}  // namespace

bool is_definition_name(std::string_view name) noexcept {
    const auto lower_or_digit = [](char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9'); };
    if (name.empty() || name.size() > max_name_length || !lower_or_digit(name.front())) {
        return false;
    }
    return std::all_of(name.begin(), name.end(), [&](char c) { return lower_or_digit(c) || c == '_' || c == '-'; });
}

void validate_definition(const RawDefinition& definition, std::string_view stem, DiagnosticSink& sink) {
    if (require(sink, definition.name, "the definition's name, which is its file name without .yaml: " +
                                           std::string(stem))) {
        if (*definition.name != stem) {
            sink.error(definition.name, "the name '" + *definition.name + "' differs from the file name " +
                                            std::string(stem) + ".yaml; expected name: " + std::string(stem) +
                                            " (devices find a definition by its file name)");
        } else if (!is_definition_name(stem)) {
            sink.error(definition.name, "'" + std::string(stem) +
                                            "' is not a definition name; expected a-z 0-9 _ -, starting with a "
                                            "letter or digit, up to 64 characters (rename the file too)");
        }
    }
    check_range(sink, definition.period, RegisterBlock::period_range);
    check_range(sink, definition.max_gap, DeviceConfig::max_gap_range);
    const auto points = check_points(definition.points, {}, sink);
    (void)check_alarms(definition.alarms, points, {}, sink);
    check_blocks(definition.blocks, nullptr, sink);
    check_identify(definition.identify, sink);
    check_registers(definition, sink);
    if (definition.behaviour.has_value() || definition.behaviour.invalid) {
        return;  // a built-in type: registers, not points (check_registers())
    }
    const bool has_points = definition.points.ok() && !definition.points.items.empty();
    const bool has_blocks = definition.blocks.ok() && !definition.blocks.items.empty();
    if (!has_points && !has_blocks && definition.points.state != RawNode::State::invalid &&
        definition.blocks.state != RawNode::State::invalid) {
        sink.error(definition.points, "a device definition needs points (or blocks); expected e.g. points: "
                                      "[{name: temperature, table: input, address: 0x0000, type: float32}]");
    }
}

}  // namespace fieldbridge::config
