#pragma once
/// @file command_decoder.hpp
/// NCMD and DCMD payloads (Sparkplug 3.0, "Operational Behavior", commands) read into
/// what the gateway may act on: which metric (by name or by alias), the datatype when
/// the host gave one, and the value. Everything else of the payload is ignored. Pure;
/// bounded by CommandLimits whatever arrives (tests/fuzz/fuzz_sparkplug_command.cpp).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "northbound/sparkplug/payload.hpp"

namespace fieldbridge::northbound::sparkplug {

/// A command payload is small: a few metrics written at once.
struct CommandLimits {
    std::size_t max_bytes = 64 * 1024;
    std::size_t max_metrics = 256;
    std::size_t max_string_bytes = 1024;
};

/// The metric a command names: an alias (NCMD/DCMD carry the alias only when the node
/// uses aliases, tck-id-payloads-alias-data-cmd-requirement), a name, or both.
struct MetricReference {
    std::optional<std::string> name;
    std::optional<std::uint64_t> alias;
    bool operator==(const MetricReference&) const = default;
};

struct CommandMetric {
    MetricReference metric;
    std::optional<DataType> datatype;  ///< as the host sent it; absent when it sent none
    Value value;  ///< never monostate; integers as payload.hpp says (without a datatype:
                  ///< int_value and long_value both as their unsigned value)
    bool operator==(const CommandMetric&) const = default;
};

struct Command {
    std::optional<std::uint64_t> timestamp;
    std::vector<CommandMetric> metrics;  ///< at least one
    bool operator==(const Command&) const = default;
};

/// A command, or why the payload is refused (one line; quote and escape it for a log).
struct CommandResult {
    std::optional<Command> command;
    std::string error;  ///< empty when command holds a value
    [[nodiscard]] bool ok() const noexcept { return command.has_value(); }
};

/// Reads an NCMD or DCMD payload. Refused: anything decode() refuses (payload_codec.hpp)
/// under @p limits, a payload without metrics, a metric with neither name nor alias or
/// with an empty name, a metric without a value (or is_null).
[[nodiscard]] CommandResult decode_command(std::string_view bytes, const CommandLimits& limits = {});

/// The payload a host would send for @p command (seq and properties aside): for tests,
/// the fuzz harness's round trip and part C's host.
[[nodiscard]] Payload command_payload(const Command& command);

}  // namespace fieldbridge::northbound::sparkplug
