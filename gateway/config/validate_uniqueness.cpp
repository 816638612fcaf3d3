#include <algorithm>
#include <cctype>
#include <system_error>

#include "config/validate.hpp"

namespace fieldbridge::config {

namespace {

/// Something that must be unique, and where it was first seen.
struct Seen {
    std::string key;    ///< e.g. 5 for a unit ID, "gripper-1" for a name
    std::string owner;  ///< key path of its first use, e.g. "lines[0].devices[1].unit_id"
    int line = 0;
};

/// Reports @p key when already in @p seen, else records it. @p what is "unit 5",
/// "device name 'gripper-1'"...; @p rule says what is expected.
void check_unique(std::vector<Seen>& seen, const std::string& key, const std::string& path, Mark mark,
                  const std::string& what, const std::string& rule, DiagnosticSink& sink) {
    const auto earlier = std::find_if(seen.begin(), seen.end(), [&](const Seen& s) { return s.key == key; });
    if (earlier != seen.end()) {
        sink.error(mark, path, what + " is already used by " + earlier->owner + " (line " +
                                   std::to_string(earlier->line) + "); expected " + rule);
        return;
    }
    seen.push_back(Seen{key, path, mark.line});
}

/// The port path with ".", "..", duplicate slashes and existing symbolic links
/// resolved, so /dev/serial/by-id/... and the /dev/ttyUSBn it points to compare equal.
/// A tcp:// port is its endpoint, the host in lower case: a device server that
/// accepts one client must never see a second connection from this gateway.
[[nodiscard]] std::string normalized_port(const std::string& port) {
    if (is_tcp_port(port)) {
        auto endpoint = parse_tcp_port(port);
        if (!endpoint) return port;  // reported by validate_lines
        std::string key = endpoint.value->to_string();
        std::transform(key.begin(), key.end(), key.begin(), [](unsigned char c) { return std::tolower(c); });
        return "tcp://" + key;
    }
    std::error_code ec;
    auto canonical = std::filesystem::weakly_canonical(std::filesystem::path(port), ec);
    if (ec) {
        canonical = std::filesystem::path(port).lexically_normal();
    }
    return canonical.string();
}

void check_unit_ids(const RawConfig& raw, std::vector<std::int64_t>& configured, DiagnosticSink& sink) {
    const std::string rule = "each unit ID once across devices, broadcast units and upstream units";
    std::vector<Seen> seen;
    const auto add = [&](const Field<std::int64_t>& unit) {
        if (!unit.has_value() || !unit_id_range.contains(*unit)) {
            return;  // missing or out of range: reported elsewhere
        }
        configured.push_back(*unit);
        check_unique(seen, std::to_string(*unit), unit.path, unit.mark, "unit " + std::to_string(*unit), rule, sink);
    };
    for (const auto& line : raw.lines.items) {
        add(line.broadcast_unit);
        for (const auto& device : line.devices.items) {
            add(device.unit_id);
        }
    }
    for (const auto& upstream : raw.upstreams.items) {
        for (const auto& unit : upstream.units.items) {
            add(unit.unit_id);
        }
    }
}

void check_names(const RawConfig& raw, DiagnosticSink& sink) {
    std::vector<Seen> lines;
    std::vector<Seen> devices;  // devices and upstream units: both are MQTT topic levels
    std::vector<Seen> upstreams;
    const auto add = [&](std::vector<Seen>& seen, const Field<std::string>& name, const std::string& kind,
                         const std::string& rule) {
        if (name.has_value() && is_valid_name(*name)) {
            check_unique(seen, *name, name.path, name.mark, kind + " '" + *name + "'", rule, sink);
        }
    };
    const std::string device_rule = "device names unique across all lines and upstream units (they are MQTT topics)";
    for (const auto& line : raw.lines.items) {
        add(lines, line.name, "line name", "unique line names");
        for (const auto& device : line.devices.items) {
            add(devices, device.name, "device name", device_rule);
        }
    }
    for (const auto& upstream : raw.upstreams.items) {
        add(upstreams, upstream.name, "upstream name", "unique upstream names");
        for (const auto& unit : upstream.units.items) {
            add(devices, unit.name, "device name", device_rule);
        }
    }
}

void check_ports_and_endpoints(const RawConfig& raw, DiagnosticSink& sink) {
    std::vector<Seen> ports;
    for (const auto& line : raw.lines.items) {
        if (line.port.has_value() && !line.port->empty()) {
            // Spec section 7: two lines on one port is an error.
            check_unique(ports, normalized_port(*line.port), line.port.path, line.port.mark,
                         "port " + *line.port, "one line per serial port or device server endpoint", sink);
        }
    }
    std::vector<Seen> endpoints;
    for (const auto& upstream : raw.upstreams.items) {
        if (upstream.host.has_value()) {
            const auto port = upstream.port.value_or(UpstreamConfig{}.port);
            const std::string endpoint = *upstream.host + ":" + std::to_string(port);
            check_unique(endpoints, endpoint, upstream.host.path, upstream.host.mark, "server " + endpoint,
                         "one upstream per server: list all its units under one upstream (one connection)", sink);
        }
    }
}

void check_rule_units(const RawConfig& raw, const std::vector<std::int64_t>& configured, DiagnosticSink& sink) {
    for (const auto& rule : raw.modbus_tcp.rules.items) {
        for (const auto& unit : rule.units.items) {
            if (unit.has_value() && *unit >= 0 && *unit <= 255 &&
                std::find(configured.begin(), configured.end(), *unit) == configured.end()) {
                sink.error(unit, "unit " + std::to_string(*unit) +
                                     " is not configured (no device, broadcast unit or upstream unit has it); "
                                     "expected a configured unit ID");
            }
        }
    }
}

}  // namespace

void validate_uniqueness(const RawConfig& raw, DiagnosticSink& sink) {
    std::vector<std::int64_t> configured;
    check_unit_ids(raw, configured, sink);
    check_names(raw, sink);
    check_ports_and_endpoints(raw, sink);
    check_rule_units(raw, configured, sink);
}

}  // namespace fieldbridge::config
