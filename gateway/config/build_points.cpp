#include "config/build_points.hpp"

#include <algorithm>

#include "config/validate.hpp"

namespace fieldbridge::config {

namespace {

[[nodiscard]] core::PointDef build_point(const RawPoint& raw, const PointDefaults& defaults) {
    core::PointDef point;
    point.name = *raw.name;
    point.table = *raw.table;
    point.address = static_cast<std::uint16_t>(*raw.address);
    point.type = effective_type(raw);
    if (raw.bit.has_value()) {
        point.bit = static_cast<std::uint8_t>(*raw.bit);
    }
    point.count = static_cast<std::uint16_t>(raw.count.value_or(0));
    point.word_order = raw.word_order.value_or(defaults.word_order);
    point.byte_order = raw.byte_order.value_or(core::ByteOrder::big);
    point.scale = raw.scale.value_or(1.0);
    point.offset = raw.offset.value_or(0.0);
    point.unit = raw.unit.value_or("");
    for (const auto& [value, label] : raw.labels.entries) {
        point.labels.push_back(core::EnumLabel{*value, *label});
    }
    point.enum_other = raw.enum_other.value_or("");
    point.enum_code = raw.enum_code.value_or(true);
    point.writable = raw.writable.value_or(false);
    point.min = raw.min.value;
    point.max = raw.max.value;
    point.period = raw.period.value_or(defaults.period);
    point.deadband = raw.deadband.value;
    point.invert = raw.invert.value_or(false);
    point.format = raw.format.value_or(core::PointFormat::number);
    point.format_text = raw.format_text.value_or("");
    return point;
}

[[nodiscard]] core::AlarmRule build_alarm(const RawAlarm& raw, const std::vector<const RawPoint*>& points) {
    core::AlarmRule alarm;
    alarm.name = *raw.name;
    alarm.point = *raw.point;
    const auto point = *std::find_if(points.begin(), points.end(), [&](const RawPoint* p) { return *p->name == alarm.point; });
    if (raw.above.has_value()) {
        alarm.condition = core::AlarmCondition::above;
        alarm.threshold = *raw.above;
    } else if (raw.below.has_value()) {
        alarm.condition = core::AlarmCondition::below;
        alarm.threshold = *raw.below;
    } else if (raw.equals.has_value()) {
        alarm.condition = core::AlarmCondition::equals;
        alarm.threshold = *alarm_value(raw.equals, *point);
    } else if (raw.not_equals.has_value()) {
        alarm.condition = core::AlarmCondition::not_equals;
        alarm.threshold = *alarm_value(raw.not_equals, *point);
    } else {
        alarm.condition = core::AlarmCondition::bit;
        alarm.bit = static_cast<std::uint8_t>(*raw.bit);
    }
    alarm.hysteresis = raw.hysteresis.value_or(0.0);
    alarm.severity = raw.severity.value_or(core::AlarmSeverity::warning);
    alarm.text = raw.text.value_or("");
    alarm.source = raw.source.value_or("");
    return alarm;
}

void add_points(const RawSeq<RawPoint>& raw, const PointDefaults& defaults, core::PointModel& model,
                std::vector<const RawPoint*>& points) {
    for (const auto& point : raw.items) {
        model.points.push_back(build_point(point, defaults));
        points.push_back(&point);
    }
}

}  // namespace

PointDefaults point_defaults(const RawDefinition* definition, const RawDevice* device) {
    PointDefaults defaults;
    if (definition != nullptr) {
        defaults.word_order = definition->word_order.value_or(defaults.word_order);
        defaults.period = definition->period.value_or(defaults.period);
        defaults.max_gap = static_cast<std::uint16_t>(definition->max_gap.value_or(defaults.max_gap));
    }
    if (device != nullptr) {
        defaults.word_order = device->word_order.value_or(defaults.word_order);
        defaults.period = device->period.value_or(defaults.period);
        defaults.max_gap = static_cast<std::uint16_t>(device->max_gap.value_or(defaults.max_gap));
    }
    return defaults;
}

core::PointModel build_point_model(const RawDefinition* definition, const RawDevice* device,
                                   const PointDefaults& defaults) {
    core::PointModel model;
    model.max_gap = defaults.max_gap;
    std::vector<const RawPoint*> points;
    if (definition != nullptr) add_points(definition->points, defaults, model, points);
    if (device != nullptr) add_points(device->points, defaults, model, points);
    for (const RawSeq<RawAlarm>* alarms : {definition ? &definition->alarms : nullptr, device ? &device->alarms : nullptr}) {
        if (alarms == nullptr) continue;
        for (const auto& alarm : alarms->items) {
            model.alarms.push_back(build_alarm(alarm, points));
        }
    }
    return model;
}

RegisterBlock build_block(const RawBlock& raw, milliseconds default_period) {
    RegisterBlock block;
    block.table = *raw.table;
    block.address = static_cast<std::uint16_t>(*raw.address);
    block.count = static_cast<std::uint16_t>(*raw.count);
    block.period = raw.period.value_or(default_period);
    block.writable = raw.writable.value_or(false);
    return block;
}

std::vector<core::RegisterDef> build_registers(const RawDefinition& raw) {
    std::vector<core::RegisterDef> rows;
    for (const RawRegister& row : raw.registers.items) {
        core::RegisterDef d;
        d.table = row.table.value_or(RegisterTable::holding);
        d.address = static_cast<std::uint16_t>(*row.address);
        d.width = static_cast<std::uint8_t>(row.width.value_or(1));
        d.count = static_cast<std::uint16_t>(row.count.value_or(1));
        d.access = *row.access;
        d.min = row.min.value_or(0);
        d.max = row.max.value_or(d.width == 2 ? 0xFFFF'FFFF : (core::is_bit_table(d.table) ? 1 : 0xFFFF));
        d.is_signed = d.min < 0;
        d.name = *row.name;
        d.motion = row.motion.value_or(false);
        d.protect = row.protect.value_or(false);
        d.auto_reset = row.auto_reset.value_or(false);
        if (row.stop.has_value()) {
            d.stop_value = static_cast<std::uint16_t>(*row.stop);
        }
        rows.push_back(std::move(d));
    }
    return rows;
}

DeviceDefinition build_definition(const RawDefinition& raw) {
    const PointDefaults defaults = point_defaults(&raw, nullptr);
    DeviceDefinition definition;
    definition.name = *raw.name;
    definition.description = raw.description.value_or("");
    definition.file = raw.file;
    definition.word_order = defaults.word_order;
    definition.period = defaults.period;
    definition.points = build_point_model(&raw, nullptr, defaults);
    for (const auto& block : raw.blocks.items) {
        definition.blocks.push_back(build_block(block, defaults.period));
    }
    if (raw.identify.ok()) {
        core::IdentifyRead identify;
        identify.table = *raw.identify.table;
        identify.address = static_cast<std::uint16_t>(*raw.identify.address);
        identify.count = static_cast<std::uint16_t>(raw.identify.count.value_or(1));
        for (const auto& value : raw.identify.expect.items) {
            identify.expect.push_back(static_cast<std::uint16_t>(*value));
        }
        definition.identify = identify;
    }
    if (raw.behaviour.has_value()) {
        definition.behaviour = *raw.behaviour;
    }
    definition.registers = build_registers(raw);
    return definition;
}

}  // namespace fieldbridge::config
