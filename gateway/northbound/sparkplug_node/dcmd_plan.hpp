#pragma once
/// @file dcmd_plan.hpp
/// A device's DCMD (Sparkplug 3.0, commands) made the MQTT commands it stands for
/// (docs/sparkplug.md, "Commands"): writable point metrics become one `write` command
/// (all values at once), a built-in writable field the operation that sets it
/// (engine::FieldSetter), `Commands/<op>` = true the operation with the parameters
/// of `Commands/<op>/<field>` given in the same DCMD or stored from earlier ones.
/// The caller runs the commands through the MQTT bridge's own parser and runner, so a
/// DCMD passes the same checks as a JSON command. Pure.
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "engine/profiles/operations.hpp"
#include "northbound/sparkplug/command_decoder.hpp"
#include "northbound/sparkplug/metric_catalogue.hpp"

namespace fieldbridge::northbound::sparkplug_node {

/// The parameter values hosts set (`Commands/<op>/<field>` metric name -> value).
using StoredArguments = std::map<std::string, sparkplug::Value, std::less<>>;

/// What a DCMD asks for, or why it is refused as a whole.
struct DcmdPlan {
    std::string error;  ///< refused: names the metric and why; nothing may be written
    /// The JSON commands (as on `<prefix>/<device>/cmd`), validated and run together.
    std::vector<nlohmann::json> commands;
    /// Parameter metrics the DCMD set: stored once the DCMD is accepted, and echoed.
    std::vector<std::pair<const sparkplug::CatalogueMetric*, sparkplug::Value>> arguments;
    [[nodiscard]] bool ok() const noexcept { return error.empty(); }
};

/// @p setters: the device type's (engine::field_setters()).
[[nodiscard]] DcmdPlan plan_dcmd(const sparkplug::MetricCatalogue& catalogue, std::string_view device,
                                 const sparkplug::Command& command, const StoredArguments& stored,
                                 std::span<const engine::FieldSetter> setters);

/// @p value as JSON for a metric of @p datatype (integers by the datatype's width and
/// sign), or an error text; @p value must fit the datatype.
struct JsonValue {
    nlohmann::json value;
    std::string error;
};
[[nodiscard]] JsonValue json_value(sparkplug::DataType datatype, const sparkplug::Value& value);

}  // namespace fieldbridge::northbound::sparkplug_node
