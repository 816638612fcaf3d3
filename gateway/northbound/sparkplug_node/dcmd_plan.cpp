#include "northbound/sparkplug_node/dcmd_plan.hpp"

#include <cmath>
#include <cstdint>
#include <limits>

#include "core/log_text.hpp"
#include "northbound/sparkplug/payload_codec.hpp"

namespace fieldbridge::northbound::sparkplug_node {
namespace {

using sparkplug::DataType;

/// The command's own id: a DCMD has none, the result is never published.
constexpr std::string_view command_id = "sparkplug-dcmd";

std::string reference_text(const sparkplug::MetricReference& reference) {
    if (reference.name) return "metric " + core::quoted(*reference.name);
    if (reference.alias) return "alias " + std::to_string(*reference.alias);
    return "a metric";
}

/// A signed value of @p bits from the 64-bit pattern, or nullopt when it does not fit
/// (an int_value carries the low 32 bits: a negative Int8..Int32 arrives as 2^32 - n).
std::optional<std::int64_t> signed_value(std::uint64_t pattern, int bits) {
    std::int64_t v = 0;
    if (bits < 64 && pattern <= 0xFFFFFFFFu) {
        v = static_cast<std::int32_t>(static_cast<std::uint32_t>(pattern));
    } else {
        v = static_cast<std::int64_t>(pattern);
    }
    if (bits == 64) return v;
    const std::int64_t low = -(std::int64_t{1} << (bits - 1));
    const std::int64_t high = (std::int64_t{1} << (bits - 1)) - 1;
    if (v < low || v > high) return std::nullopt;
    return v;
}

int width(DataType type) {
    switch (type) {
    case DataType::int8:
    case DataType::uint8:
        return 8;
    case DataType::int16:
    case DataType::uint16:
        return 16;
    case DataType::int32:
    case DataType::uint32:
        return 32;
    default:
        return 64;
    }
}

}  // namespace

JsonValue json_value(DataType datatype, const sparkplug::Value& value) {
    const std::string wanted = sparkplug::datatype_name(datatype);
    switch (datatype) {
    case DataType::int8:
    case DataType::int16:
    case DataType::int32:
    case DataType::int64: {
        const auto* pattern = std::get_if<std::uint64_t>(&value);
        if (pattern == nullptr) return {nullptr, "an " + wanted + " value is expected"};
        const auto v = signed_value(*pattern, width(datatype));
        if (!v) return {nullptr, "the value does not fit " + wanted};
        return {*v, ""};
    }
    case DataType::uint8:
    case DataType::uint16:
    case DataType::uint32:
    case DataType::uint64: {
        const auto* pattern = std::get_if<std::uint64_t>(&value);
        if (pattern == nullptr) return {nullptr, "a " + wanted + " value is expected"};
        const int bits = width(datatype);
        if (bits < 64 && *pattern >> bits != 0) return {nullptr, "the value does not fit " + wanted};
        return {*pattern, ""};
    }
    case DataType::float32:
    case DataType::float64: {
        double v = 0;
        if (const auto* f = std::get_if<float>(&value)) {
            v = *f;
        } else if (const auto* d = std::get_if<double>(&value)) {
            v = *d;
        } else {
            return {nullptr, "a " + wanted + " value is expected"};
        }
        if (!std::isfinite(v)) return {nullptr, "the value is not a finite number"};
        return {v, ""};
    }
    case DataType::boolean: {
        const auto* b = std::get_if<bool>(&value);
        if (b == nullptr) return {nullptr, "a Boolean value is expected"};
        return {*b, ""};
    }
    case DataType::string:
    case DataType::text: {
        const auto* text = std::get_if<std::string>(&value);
        if (text == nullptr) return {nullptr, "a String value is expected"};
        return {*text, ""};
    }
    default:
        return {nullptr, "its datatype " + wanted + " cannot be written"};
    }
}

DcmdPlan plan_dcmd(const sparkplug::MetricCatalogue& catalogue, std::string_view device,
                   const sparkplug::Command& command, const StoredArguments& stored,
                   std::span<const engine::FieldSetter> setters) {
    DcmdPlan plan;
    nlohmann::json values = nlohmann::json::object();  // the `write` command's
    std::vector<nlohmann::json> field_ops;
    std::vector<std::string> triggered;
    StoredArguments arguments;  // this DCMD's parameters
    const auto refuse = [&plan](std::string why) {
        plan.error = std::move(why);
        plan.commands.clear();
        plan.arguments.clear();
        return plan;
    };
    for (const sparkplug::CommandMetric& entry : command.metrics) {
        const sparkplug::CatalogueMetric* metric = catalogue.find(device, entry.metric);
        if (metric == nullptr) return refuse(reference_text(entry.metric) + " is not a metric of this device");
        const std::string name = core::quoted(metric->name);
        if (entry.datatype && *entry.datatype != metric->datatype) {
            return refuse("metric " + name + " is " + sparkplug::datatype_name(metric->datatype) + ", the DCMD says " +
                          sparkplug::datatype_name(*entry.datatype));
        }
        if (!metric->writable) return refuse("metric " + name + " is read-only");
        JsonValue json = json_value(metric->datatype, entry.value);
        if (!json.error.empty()) return refuse("metric " + name + ": " + json.error);
        if (metric->is_command()) {
            if (!metric->argument.empty()) {
                arguments[metric->name] = entry.value;
                plan.arguments.emplace_back(metric, entry.value);
            } else if (json.value.get<bool>()) {
                triggered.push_back(metric->op);
            }
            continue;
        }
        if (metric->point != nullptr) {
            values[metric->point->name] = std::move(json.value);
            continue;
        }
        const engine::FieldSetter* setter = nullptr;
        for (const engine::FieldSetter& s : setters) {
            if (s.field == metric->field) setter = &s;
        }
        if (setter == nullptr) return refuse("metric " + name + " is read-only");
        nlohmann::json op{{"id", command_id}, {"op", setter->op}};
        op[std::string(setter->argument)] = std::move(json.value);
        field_ops.push_back(std::move(op));
    }
    if (!values.empty()) plan.commands.push_back({{"id", command_id}, {"op", "write"}, {"values", std::move(values)}});
    for (auto& op : field_ops) plan.commands.push_back(std::move(op));
    // A triggered op takes its parameters from this DCMD first, then from earlier ones.
    for (const std::string& op : triggered) {
        nlohmann::json json{{"id", command_id}, {"op", op}};
        for (const sparkplug::CatalogueMetric& metric : catalogue.metrics(device)) {
            if (metric.op != op || metric.argument.empty()) continue;
            const sparkplug::Value* value = nullptr;
            if (const auto it = arguments.find(metric.name); it != arguments.end()) {
                value = &it->second;
            } else if (const auto kept = stored.find(metric.name); kept != stored.end()) {
                value = &kept->second;
            }
            if (value == nullptr) continue;  // the parser says whether the op needs it
            JsonValue converted = json_value(metric.datatype, *value);
            if (!converted.error.empty()) continue;
            json[metric.argument] = std::move(converted.value);
        }
        plan.commands.push_back(std::move(json));
    }
    return plan;
}

}  // namespace fieldbridge::northbound::sparkplug_node
