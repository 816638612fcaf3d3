#include "northbound/sparkplug/metric_catalogue.hpp"

#include <cmath>
#include <limits>
#include <type_traits>
#include <variant>

#include "northbound/mqtt/state_throttle.hpp"

namespace fieldbridge::northbound::sparkplug {
namespace {

DataType integer_datatype(core::PointType type) {
    switch (type) {
    case core::PointType::boolean:
        return DataType::boolean;
    case core::PointType::int16:
        return DataType::int16;
    case core::PointType::uint16:
        return DataType::uint16;
    case core::PointType::int32:
        return DataType::int32;
    case core::PointType::uint32:
        return DataType::uint32;
    case core::PointType::int64:
        return DataType::int64;
    case core::PointType::uint64:
        return DataType::uint64;
    case core::PointType::float32:
        return DataType::float32;
    case core::PointType::float64:
        return DataType::float64;
    case core::PointType::string:
        return DataType::string;
    }
    return DataType::unknown;
}

// A field without a point: its datatype from its value (a list: each element a Double).
DataType value_datatype(const engine::FieldValue& value) {
    return std::visit(
        [](const auto& v) {
            using V = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<V, bool>) return DataType::boolean;
            if constexpr (std::is_same_v<V, std::int64_t>) return DataType::int64;
            if constexpr (std::is_same_v<V, std::string>) return DataType::string;
            return DataType::float64;  // double, and the elements of a list
        },
        value);
}

bool is_integer(DataType type) {
    switch (type) {
    case DataType::int8:
    case DataType::int16:
    case DataType::int32:
    case DataType::int64:
    case DataType::uint8:
    case DataType::uint16:
    case DataType::uint32:
    case DataType::uint64:
        return true;
    default:
        return false;
    }
}

const std::vector<CatalogueMetric> no_metrics;

DataType argument_datatype(const engine::FieldType& type) {
    return std::visit(
        [](const auto& t) {
            using T = std::decay_t<decltype(t)>;
            if constexpr (std::is_same_v<T, engine::NumberField>) return DataType::float64;
            if constexpr (std::is_same_v<T, engine::IntegerField>) return DataType::int64;
            if constexpr (std::is_same_v<T, engine::BooleanField>) return DataType::boolean;
            return DataType::string;  // ChoiceField
        },
        type);
}

}  // namespace

DataType point_datatype(const core::PointDef& point) {
    if (point.format != core::PointFormat::number) return DataType::string;  // "0x00000078", "V3.0.1.884"
    const DataType type = integer_datatype(point.type);
    const bool scaled = point.scale != 1.0 || point.offset != 0.0;
    if (scaled && is_integer(type)) return DataType::float64;
    return type;
}

std::uint64_t MetricCatalogue::alias_for(std::string_view device, std::string_view metric) {
    const auto key = std::make_pair(std::string(device), std::string(metric));
    const auto known = aliases_.find(key);
    if (known != aliases_.end()) return known->second;
    const std::uint64_t alias = next_alias_++;
    aliases_.emplace(key, alias);
    return alias;
}

void MetricCatalogue::add_metric(Device& device, std::string_view device_name, CatalogueMetric metric) {
    for (const CatalogueMetric& known : device.metrics) {
        if (known.name == metric.name) return;
    }
    metric.alias = alias_for(device_name, metric.name);
    device.metrics.push_back(std::move(metric));
}

bool MetricCatalogue::add_device(const DeviceShape& shape) {
    Device& device = devices_[shape.name];
    const std::size_t before = device.metrics.size();
    device.deadband = shape.deadband;
    // Points first, in the model's order: known before the first poll answers.
    if (shape.points != nullptr) {
        for (const core::PointDef& point : shape.points->points) {
            if (point.deadband) device.deadband[point.name] = *point.deadband;
            if (!point.labels.empty()) {
                // An enum point is two fields of the JSON state: the label under the
                // point's name and the code under <name>_code (engine/profiles/point_state.cpp).
                add_metric(device, shape.name,
                           CatalogueMetric{point.name, point.name, std::nullopt, 0, DataType::string, point.unit,
                                           false, &point});
                if (!point.enum_code) continue;  // enum_code: false, the label alone
                const std::string code = point.name + "_code";
                add_metric(device, shape.name,
                           CatalogueMetric{code, code, std::nullopt, 0, integer_datatype(point.type), "",
                                           point.writable, &point});
                continue;
            }
            add_metric(device, shape.name,
                       CatalogueMetric{point.name, point.name, std::nullopt, 0, point_datatype(point), point.unit,
                                       point.writable, &point});
        }
    }
    // Then the fields of the state no point names, in the state's order.
    for (const engine::Field& field : shape.state.fields) {
        const bool writable = shape.writable_fields.contains(field.name);
        if (const auto* list = std::get_if<std::vector<double>>(&field.value)) {
            // A list (R6 axes_deg): one Double per element, `<field>/<index>`.
            for (std::size_t i = 0; i < list->size(); ++i) {
                add_metric(device, shape.name,
                           CatalogueMetric{field.name + "/" + std::to_string(i), field.name, i, 0, DataType::float64,
                                           field.unit, writable, nullptr});
            }
            continue;
        }
        add_metric(device, shape.name,
                   CatalogueMetric{field.name, field.name, std::nullopt, 0, value_datatype(field.value), field.unit,
                                   writable, nullptr});
    }
    // Then the type's operations (they never depend on the state).
    for (const engine::Operation& op : shape.operations.operations) {
        const std::string trigger = std::string(commands_folder) + std::string(op.name);
        add_metric(device, shape.name,
                   CatalogueMetric{trigger, "", std::nullopt, 0, DataType::boolean, "", true, nullptr,
                                   std::string(op.name), ""});
        for (const engine::OperationField& field : op.fields) {
            add_metric(device, shape.name,
                       CatalogueMetric{trigger + "/" + std::string(field.name), "", std::nullopt, 0,
                                       argument_datatype(field.type), "", true, nullptr, std::string(op.name),
                                       std::string(field.name)});
        }
    }
    return device.metrics.size() != before;
}

void MetricCatalogue::remove_device(std::string_view device) {
    const auto it = devices_.find(device);
    if (it != devices_.end()) devices_.erase(it);
}

const std::vector<CatalogueMetric>& MetricCatalogue::metrics(std::string_view device) const {
    const auto it = devices_.find(device);
    return it == devices_.end() ? no_metrics : it->second.metrics;
}

bool MetricCatalogue::covers(std::string_view device, const engine::DecodedState& state) const {
    const auto& known = metrics(device);
    for (const engine::Field& field : state.fields) {
        std::size_t needed = 1;
        if (const auto* list = std::get_if<std::vector<double>>(&field.value)) needed = list->size();
        std::size_t found = 0;
        for (const CatalogueMetric& metric : known) {
            if (metric.field == field.name) ++found;
        }
        if (found < needed) return false;
    }
    return true;
}

Value MetricCatalogue::metric_value(const CatalogueMetric& metric, const engine::FieldValue& value) {
    if (metric.element) {
        const auto* list = std::get_if<std::vector<double>>(&value);
        if (list == nullptr || *metric.element >= list->size()) return std::monostate{};
        return (*list)[*metric.element];
    }
    const DataType type = metric.datatype;
    if (const auto* b = std::get_if<bool>(&value)) {
        if (type == DataType::boolean) return *b;
        return std::monostate{};
    }
    if (const auto* text = std::get_if<std::string>(&value)) {
        if (type == DataType::string || type == DataType::text) return *text;
        return std::monostate{};
    }
    if (const auto* i = std::get_if<std::int64_t>(&value)) {
        if (is_integer(type)) return static_cast<std::uint64_t>(*i);
        if (type == DataType::float64) return static_cast<double>(*i);
        if (type == DataType::float32) return static_cast<float>(*i);
        // An enum point's code without a label stands in for the label (the JSON shows
        // the number; the String metric its decimal text).
        if (type == DataType::string) return std::to_string(*i);
        return std::monostate{};
    }
    if (const auto* d = std::get_if<double>(&value)) {
        if (type == DataType::float64) return *d;
        if (type == DataType::float32) return static_cast<float>(*d);
        // A uint64 point above INT64_MAX decodes as a double (engine/points/point_codec.hpp).
        if (type == DataType::uint64 && *d >= 0 && *d < 18446744073709551616.0) {
            return static_cast<std::uint64_t>(*d);
        }
        return std::monostate{};
    }
    return std::monostate{};
}

std::vector<Metric> MetricCatalogue::birth_metrics(std::string_view device, const engine::DecodedState& state,
                                                   std::uint64_t time_ms, bool aliases) const {
    std::vector<Metric> out;
    for (const CatalogueMetric& known : metrics(device)) {
        Metric metric;
        // tck-id-payloads-alias-birth-requirement: a birth has name and alias.
        metric.name = known.name;
        if (aliases) metric.alias = known.alias;
        metric.timestamp = time_ms;
        metric.datatype = known.datatype;  // tck-id-payloads-metric-datatype-req
        if (const engine::Field* field = state.find(known.field)) {
            metric.value = metric_value(known, field->value);
        }
        if (!known.unit.empty()) {
            metric.properties.push_back(Property{std::string(unit_property), DataType::string, known.unit});
        }
        if (known.writable) {
            metric.properties.push_back(Property{std::string(writable_property), DataType::boolean, true});
        }
        out.push_back(std::move(metric));
    }
    return out;
}

std::vector<Metric> MetricCatalogue::changed_metrics(std::string_view device, const engine::DecodedState& published,
                                                     const engine::DecodedState& now, std::uint64_t time_ms,
                                                     bool aliases) const {
    std::vector<Metric> out;
    const auto it = devices_.find(device);
    if (it == devices_.end()) return out;
    const Device& known = it->second;
    for (const CatalogueMetric& entry : known.metrics) {
        const engine::Field* after = now.find(entry.field);
        if (after == nullptr) continue;
        const engine::Field* before = published.find(entry.field);
        if (before != nullptr && !mqtt::field_differs(*before, *after, known.deadband)) continue;
        Value value = metric_value(entry, after->value);
        // A list that moved: only the elements that did.
        if (entry.element && before != nullptr && metric_value(entry, before->value) == value) continue;
        Metric metric;
        // tck-id-payloads-alias-data-cmd-requirement: DATA carries the alias only.
        if (aliases) {
            metric.alias = entry.alias;
        } else {
            metric.name = entry.name;
        }
        metric.timestamp = time_ms;  // tck-id-payloads-name-birth-data-requirement
        metric.value = std::move(value);
        out.push_back(std::move(metric));
    }
    return out;
}

const CatalogueMetric* MetricCatalogue::find(std::string_view device, const MetricReference& reference) const {
    for (const CatalogueMetric& metric : metrics(device)) {
        if (reference.alias) {
            if (metric.alias == *reference.alias) return &metric;
        } else if (reference.name && metric.name == *reference.name) {
            return &metric;
        }
    }
    return nullptr;
}

}  // namespace fieldbridge::northbound::sparkplug
