#include <algorithm>

#include "config/validate.hpp"

namespace fieldbridge::config {

namespace {

[[nodiscard]] std::string type_name(DeviceType type) { return std::string(to_string(type)); }

/// Device addresses by type; broadcast addresses are named as such.
void check_address(const RawDevice& device, DiagnosticSink& sink) {
    const auto& address = device.address;
    if (!address.has_value()) {
        return;
    }
    if (!device.type.has_value()) {
        // The type is missing or wrong (reported): check what holds for every type.
        check_range(sink, address, Range<std::int64_t>{1, 254});
        return;
    }
    const DeviceType type = *device.type;
    const auto range = address_range(type);
    const std::string expected =
        "expected " + std::to_string(range.min) + ".." + std::to_string(range.max) + " for " + type_name(type);
    // 0 is the Modbus broadcast address (Modbus over serial line V1.02 section 2.1);
    // the EXCD203MB broadcasts on 0xFF instead (seed 002 section 5).
    if (*address == 0 || *address == broadcast_address(type).value) {
        const std::string which =
            *address == 0 ? "0 is the broadcast address" : "0xFF (255) is the EXCD203MB broadcast address";
        sink.error(address, which + " and cannot be a device address (configure a line broadcast_unit to "
                                    "broadcast); " + expected);
        return;
    }
    if (*address < range.min || *address > range.max) {
        sink.error(address, std::to_string(*address) + " is outside the " + type_name(type) + " address range; " +
                                expected);
    }
}

}  // namespace

void check_blocks(const RawSeq<RawBlock>& blocks, const RawSeq<RawBlock>* earlier, DiagnosticSink& sink) {
    struct Span {
        RegisterTable table;
        std::int64_t first;
        std::int64_t last;
        std::string path;
    };
    std::vector<Span> valid;  // blocks already checked, for the overlap test
    if (earlier != nullptr) {
        for (const RawBlock& block : earlier->items) {  // a valid definition's
            valid.push_back(Span{*block.table, *block.address, *block.address + *block.count - 1,
                                 block.path + " of the definition"});
        }
    }
    for (std::size_t i = 0; i < blocks.items.size(); ++i) {
        const RawBlock& block = blocks.items[i];
        if (!block.ok()) {
            continue;
        }
        require(sink, block.table, "one of coils, discrete_inputs, holding, input");
        const bool has_address = require(sink, block.address, "the first register address, e.g. 0x0000") &&
                                 check_range(sink, block.address, Range<std::int64_t>{0, 0xFFFF});
        bool has_count = require(sink, block.count, "the number of registers or bits to read");
        if (has_count && !block.table.has_value()) {
            // Without a (valid) table, only the widest limit can be checked.
            has_count = check_range(sink, block.count, Range<std::int64_t>{1, RegisterBlock::max_bits});
        } else if (has_count) {
            const bool bits =
                *block.table == RegisterTable::coils || *block.table == RegisterTable::discrete_inputs;
            const std::int64_t max = bits ? RegisterBlock::max_bits : RegisterBlock::max_registers;
            if (*block.count < 1 || *block.count > max) {
                // Modbus Application Protocol V1.1b3 sections 6.1-6.4.
                sink.error(block.count, std::to_string(*block.count) + " is out of range; one read carries 1.." +
                                            std::to_string(max) + (bits ? " bits" : " registers") +
                                            ": split the block");
                has_count = false;
            }
        }
        if (has_address && has_count && *block.address + *block.count - 1 > 0xFFFF) {
            sink.error(block.count, "the block " + hex16(*block.address) + " + " + std::to_string(*block.count) +
                                        " runs past register 0xFFFF; expected address + count - 1 <= 0xFFFF");
            has_count = false;
        }
        check_range(sink, block.period, RegisterBlock::period_range);
        if (block.writable.value_or(false) && block.table.has_value() &&
            (*block.table == RegisterTable::input || *block.table == RegisterTable::discrete_inputs)) {
            sink.error(block.writable, "table " + std::string(to_string(*block.table)) +
                                           " is read-only in Modbus; expected writable: false (or table: " +
                                           (*block.table == RegisterTable::input ? "holding" : "coils") + ")");
        }
        if (!has_address || !has_count || !block.table.has_value()) {
            continue;
        }
        const std::int64_t first = *block.address;
        const std::int64_t last = first + *block.count - 1;
        for (const auto& other : valid) {
            if (other.table == *block.table && first <= other.last && other.first <= last) {
                sink.error(block, std::string(to_string(*block.table)) + " " + hex16(first) + "-" + hex16(last) +
                                      " overlaps " + other.path + " (" + hex16(other.first) + "-" +
                                      hex16(other.last) + "); blocks of one table must not overlap: merge or split them");
            }
        }
        valid.push_back(Span{*block.table, first, last, block.path});
    }
}

namespace {

/// `points:`, `alarms:`, `max_gap` and `period` of a generic device, with the
/// definition's (already checked in its own file) as the earlier ones.
void check_point_keys(const RawDevice& device, DiagnosticSink& sink) {
    const RawDefinition* definition = device.definition.get();
    std::vector<PointSpan> earlier;
    std::vector<std::string> alarm_names;
    if (definition != nullptr) {
        DiagnosticSink scratch(definition->file);  // the definition is valid: nothing is reported
        earlier = check_points(definition->points, {}, scratch);
        alarm_names = check_alarms(definition->alarms, earlier, {}, scratch);
    }
    const auto points = check_points(device.points, std::move(earlier), sink);
    (void)check_alarms(device.alarms, points, std::move(alarm_names), sink);
    check_range(sink, device.max_gap, DeviceConfig::max_gap_range);
    check_range(sink, device.period, RegisterBlock::period_range);
}

/// Keys that only some types have.
void check_type_specific(const RawDevice& device, DiagnosticSink& sink) {
    if (!device.type.has_value()) {
        return;
    }
    const DeviceType type = *device.type;
    const std::string of_type = " (this device is " + type_name(type) + ")";
    if (device.word_order.has_value() && !has_register_pairs(type)) {
        sink.error(device.word_order, "word_order applies only to excd203mb and modbus devices (32-bit register "
                                      "pairs)" + of_type + "; remove it");
    }
    if (type == DeviceType::wtec_ascii) {
        if (require(sink, device.stroke, "the encoder counts at 100 % (e.g. 20000): wtec-ascii needs it to map "
                                         "positions to 0-100")) {
            check_range(sink, device.stroke, DeviceConfig::stroke_range);
        }
    } else if (device.stroke.has_value()) {
        sink.error(device.stroke, "stroke applies only to wtec-ascii devices" + of_type + "; remove it");
    }
    if (type == DeviceType::modbus) {
        const bool has_points = device.points.ok() && !device.points.items.empty();
        if (device.definition == nullptr && !has_points) {
            if (device.blocks.absent()) {
                sink.error(device.blocks, "required key is missing; a generic modbus device needs points or register "
                                          "blocks, e.g. points: [{name: voltage, table: input, address: 0x0000}] or "
                                          "blocks: [{table: holding, address: 0x0000, count: 10}]");
            } else if (device.blocks.ok() && device.blocks.items.empty()) {
                sink.error(device.blocks, "is empty; a generic modbus device needs points or at least one register "
                                          "block");
            }
        }
        if (!device.poll.absent()) {
            sink.error(device.poll, "generic modbus devices are polled per point and block; set period (the "
                                    "points' default), points[].period or blocks[].period instead");
        }
        check_point_keys(device, sink);
    } else {
        if (!device.blocks.absent()) {
            sink.error(device.blocks, "blocks apply only to generic modbus devices" + of_type +
                                          "; the register map of this type is its definition file (docs/devices.md, "
                                          "\"Built-in types\")");
        }
        const std::string generic_only = " apply only to generic modbus devices and device definitions" + of_type +
                                         "; remove them";
        if (!device.points.absent()) sink.error(device.points, "points" + generic_only);
        if (!device.alarms.absent()) sink.error(device.alarms, "alarms" + generic_only);
        if (device.max_gap.has_value()) sink.error(device.max_gap, "max_gap" + generic_only);
        if (device.period.has_value()) sink.error(device.period, "period" + generic_only);
    }
    check_blocks(device.blocks, device.definition ? &device.definition->blocks : nullptr, sink);
}

void check_device(const RawDevice& device, std::chrono::milliseconds line_response_timeout, DiagnosticSink& sink) {
    if (require(sink, device.name, "a device name such as gripper-1")) {
        check_name(sink, device.name);
    }
    require(sink, device.type_name,
            "one of hiwin-xeg, excd203mb, wtec-rtu, wtec-ascii, modbus, or the name of a device definition");
    if (require(sink, device.address, "the device's bus address")) {
        check_address(device, sink);
    }
    if (require(sink, device.unit_id, "the Modbus TCP unit ID that reaches this device (1..247)")) {
        check_range(sink, device.unit_id, unit_id_range);
    }
    check_range(sink, device.max_age, DeviceConfig::max_age_range);
    if (check_range(sink, device.command_ttl, DeviceConfig::command_ttl_range) &&
        *device.command_ttl < line_response_timeout) {
        // A command may have to wait for the transaction in flight, which can last a
        // whole response_timeout when its device does not answer (spec section 3 rule 2).
        sink.error(device.command_ttl, format_duration(*device.command_ttl) +
                                           " is shorter than the line's response_timeout (" +
                                           format_duration(line_response_timeout) +
                                           "): a command waiting behind one unanswered request would always "
                                           "expire; expected at least " + format_duration(line_response_timeout));
    }
    check_range(sink, device.delay_before_command, DeviceConfig::delay_before_command_range);
    check_range(sink, device.request_gap, DeviceConfig::pacing_range);
    check_range(sink, device.first_request_delay, DeviceConfig::pacing_range);
    check_range(sink, device.queue_limit, DeviceConfig::queue_limit_range);
    if (device.poll.ok()) {
        check_range(sink, device.poll.fast, PollConfig::period_range);
        check_range(sink, device.poll.slow, PollConfig::period_range);
        check_range(sink, device.poll.motion, PollConfig::period_range);
    }
    check_type_specific(device, sink);
}

}  // namespace

void validate_devices(const RawLine& line, DiagnosticSink& sink) {
    const auto response_timeout = line.response_timeout.value_or(LineConfig{}.response_timeout);
    for (std::size_t i = 0; i < line.devices.items.size(); ++i) {
        const RawDevice& device = line.devices.items[i];
        if (!device.ok()) {
            continue;
        }
        check_device(device, response_timeout, sink);
        if (!device.address.has_value()) {
            continue;
        }
        // Two devices with one address on one bus would both answer (spec section 7).
        for (std::size_t j = 0; j < i; ++j) {
            const RawDevice& other = line.devices.items[j];
            if (other.ok() && other.address.has_value() && *other.address == *device.address) {
                sink.error(device.address, "address " + std::to_string(*device.address) + " is already used by " +
                                               other.path + (other.name.has_value() ? " (" + *other.name + ")" : "") +
                                               " on this line; expected one address per device on a bus");
                break;
            }
        }
    }
}

}  // namespace fieldbridge::config
