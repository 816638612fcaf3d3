#include "northbound/sparkplug/command_decoder.hpp"

#include "northbound/sparkplug/payload_codec.hpp"

namespace fieldbridge::northbound::sparkplug {
namespace {

std::string describe(const Metric& metric, std::size_t index) {
    std::string label = "metric " + std::to_string(index);
    if (metric.name) label += " '" + *metric.name + "'";
    if (metric.alias) label += " (alias " + std::to_string(*metric.alias) + ")";
    return label;
}

}  // namespace

CommandResult decode_command(std::string_view bytes, const CommandLimits& limits) {
    DecodeLimits decode_limits;
    decode_limits.max_bytes = limits.max_bytes;
    decode_limits.max_metrics = limits.max_metrics;
    decode_limits.max_string_bytes = limits.max_string_bytes;
    // What unpacking a payload of max_bytes can need: its structures are a few times
    // the size of their bytes (docs/sparkplug.md, "Commands").
    decode_limits.max_memory = 16 * limits.max_bytes + 64 * 1024;
    DecodeResult decoded = decode(bytes, decode_limits);
    CommandResult result;
    if (!decoded.ok()) {
        result.error = "the payload does not decode: " + decoded.error;
        return result;
    }
    Payload& payload = *decoded.payload;
    if (payload.metrics.empty()) {
        result.error = "the command holds no metric";
        return result;
    }
    Command command;
    command.timestamp = payload.timestamp;
    for (std::size_t i = 0; i < payload.metrics.size(); ++i) {
        Metric& metric = payload.metrics[i];
        if (!metric.name && !metric.alias) {
            result.error = describe(metric, i) + " has neither a name nor an alias";
            return result;
        }
        if (metric.name && metric.name->empty()) {
            result.error = describe(metric, i) + " has an empty name";
            return result;
        }
        if (std::holds_alternative<std::monostate>(metric.value)) {
            result.error = describe(metric, i) + " has no value";
            return result;
        }
        command.metrics.push_back(
            CommandMetric{MetricReference{std::move(metric.name), metric.alias}, metric.datatype,
                          std::move(metric.value)});
    }
    result.command = std::move(command);
    return result;
}

Payload command_payload(const Command& command) {
    Payload payload;
    payload.timestamp = command.timestamp;
    for (const CommandMetric& in : command.metrics) {
        Metric metric;
        metric.name = in.metric.name;
        metric.alias = in.metric.alias;
        metric.datatype = in.datatype;
        metric.value = in.value;
        payload.metrics.push_back(std::move(metric));
    }
    return payload;
}

}  // namespace fieldbridge::northbound::sparkplug
