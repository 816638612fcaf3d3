#pragma once
/// @file metric_catalogue.hpp
/// The Sparkplug metrics of the node's devices (docs/sparkplug.md, "Names and
/// datatypes"): each device metric named as the field of the device's JSON state
/// (northbound/mqtt/payloads.cpp, `fields`), with a datatype from its point (or from
/// the field's value for a built-in type), an alias unique across the node and stable
/// for the life of the catalogue, its unit (`engUnit`) and whether it is writable
/// (`writable`). It builds the DBIRTH metrics of a device and the DDATA metrics of what
/// changed between two states (the points' deadbands apply). Pure: the caller passes
/// states and times; what to publish when is the session's business.
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "core/point.hpp"
#include "engine/profiles/device_profile.hpp"
#include "northbound/sparkplug/command_decoder.hpp"
#include "northbound/sparkplug/payload.hpp"

namespace fieldbridge::northbound::sparkplug {

/// Property keys of a birth's metrics.
inline constexpr std::string_view unit_property = "engUnit";      ///< String: the unit
inline constexpr std::string_view writable_property = "writable";  ///< Boolean true: a DCMD may write it

/// What the catalogue needs of one device (part C fills it from mqtt::DeviceSource).
struct DeviceShape {
    std::string name;                          ///< the device id (the configured name)
    /// Its points, if any (DeviceSource::points()); they must outlive the catalogue
    /// (CatalogueMetric::point points into them).
    const core::PointModel* points = nullptr;
    engine::DecodedState state;                ///< a decoded state: the built-in fields it has
    std::set<std::string, std::less<>> writable_fields;  ///< fields without a point that are writable
    /// Smallest change published per field (`mqtt.deadband`); a point's own deadband wins.
    std::map<std::string, double, std::less<>> deadband;
    /// Its type's operations: each becomes the command metrics `Commands/<op>` (Boolean,
    /// a DCMD of true runs it) and `Commands/<op>/<field>` per field (docs/sparkplug.md,
    /// "Commands").
    engine::OperationSet operations{};
};

/// The folder of the command metrics.
inline constexpr std::string_view commands_folder = "Commands/";

/// One metric of a device.
struct CatalogueMetric {
    std::string name;        ///< the Sparkplug metric name (= the JSON field; `<field>/<i>` for list elements)
    std::string field;       ///< the JSON state field it shows
    std::optional<std::size_t> element;  ///< the index in a list field (R6 `axes_deg`)
    std::uint64_t alias = 0;
    DataType datatype = DataType::unknown;
    std::string unit;
    bool writable = false;
    const core::PointDef* point = nullptr;  ///< the point behind it, if any
    /// A command metric: the operation (empty for a state metric) and, for a
    /// parameter, the operation's field (empty for `Commands/<op>` itself).
    std::string op{};
    std::string argument{};
    [[nodiscard]] bool is_command() const noexcept { return !op.empty(); }
};

class MetricCatalogue {
public:
    /// Aliases are handed out from @p first_alias up (the node's own metrics take the
    /// ones below).
    explicit MetricCatalogue(std::uint64_t first_alias = 1) : next_alias_(first_alias) {}

    /// Adds @p device or, when it is known, adds the metrics of fields it did not have
    /// (a metric keeps its alias while the catalogue lives, also across removal and
    /// re-adding). True when the device's metric list changed: it needs a new DBIRTH.
    bool add_device(const DeviceShape& device);
    /// Forgets @p device's metrics (its aliases stay reserved for it).
    void remove_device(std::string_view device);

    /// The device's metrics in birth order (points first, in the model's order, then the
    /// other fields in the state's order, then the command metrics); empty for an
    /// unknown device.
    [[nodiscard]] const std::vector<CatalogueMetric>& metrics(std::string_view device) const;

    /// False when @p state has a field the catalogue has no metric for (add_device()
    /// it again, then re-birth the device).
    [[nodiscard]] bool covers(std::string_view device, const engine::DecodedState& state) const;

    /// A DBIRTH's metrics: every metric with name, alias (when @p aliases), datatype,
    /// timestamp @p time_ms, its value in @p state (null when it has none) and the
    /// properties engUnit / writable.
    [[nodiscard]] std::vector<Metric> birth_metrics(std::string_view device, const engine::DecodedState& state,
                                                    std::uint64_t time_ms, bool aliases) const;

    /// A DDATA's metrics: those whose field differs between @p published and @p now by
    /// more than its deadband, by alias only (by name when not @p aliases), with the
    /// datatype left out (the birth has it), and timestamp @p time_ms.
    [[nodiscard]] std::vector<Metric> changed_metrics(std::string_view device, const engine::DecodedState& published,
                                                      const engine::DecodedState& now, std::uint64_t time_ms,
                                                      bool aliases) const;

    /// The metric a command names (alias first, else name); nullptr when none.
    [[nodiscard]] const CatalogueMetric* find(std::string_view device, const MetricReference& reference) const;

    /// @p value of field @p field as the metric's datatype wants it (monostate when the
    /// value does not fit, e.g. a string for a number).
    [[nodiscard]] static Value metric_value(const CatalogueMetric& metric, const engine::FieldValue& value);

private:
    struct Device {
        std::vector<CatalogueMetric> metrics;
        std::map<std::string, double, std::less<>> deadband;
    };
    std::uint64_t alias_for(std::string_view device, std::string_view metric);
    void add_metric(Device& device, std::string_view device_name, CatalogueMetric metric);

    std::map<std::string, Device, std::less<>> devices_;
    std::map<std::pair<std::string, std::string>, std::uint64_t> aliases_;  ///< (device, metric) -> alias
    std::uint64_t next_alias_;
};

/// The Sparkplug datatype of a point's values: its type (int16 -> Int16, ..., float32 ->
/// Float, float64 -> Double, bool -> Boolean, string -> String), Double for an integer
/// point with a scale or an offset (its engineering value).
[[nodiscard]] DataType point_datatype(const core::PointDef& point);

}  // namespace fieldbridge::northbound::sparkplug
