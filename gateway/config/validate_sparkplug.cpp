// The sparkplug: section (docs/configuration.md, "sparkplug"): its servers, the
// connection settings it shares with mqtt:, and the Sparkplug ID rules for the group,
// the edge node and every device of the configuration (each becomes a Sparkplug device).
#include <filesystem>
#include <system_error>

#include "config/mqtt_uri.hpp"
#include "config/sparkplug_ids.hpp"
#include "config/validate.hpp"

namespace fieldbridge::config {

namespace {

void check_id(DiagnosticSink& sink, const Field<std::string>& field, std::string_view what) {
    if (!field.has_value()) return;
    if (const auto problem = sparkplug_id_problem(*field)) {
        sink.error(field, "'" + *field + "' " + *problem + "; expected a Sparkplug " + std::string(what) +
                              " (non-empty UTF-8 without +, / or #)");
    }
}

/// Each server is tcp:// or ssl://; returns whether one is ssl://.
bool check_servers(const RawSparkplug& sparkplug, DiagnosticSink& sink) {
    bool any_tls = false;
    if (sparkplug.servers.absent()) {
        sink.error(sparkplug.servers, "required key is missing; expected a list of servers, e.g. "
                                      "[tcp://broker-a:1883, tcp://broker-b:1883]");
        return false;
    }
    if (sparkplug.servers.ok() && sparkplug.servers.items.empty()) {
        sink.error(sparkplug.servers, "the list is empty; expected at least one server, e.g. tcp://broker:1883");
    }
    for (const auto& server : sparkplug.servers.items) {
        if (!server.has_value()) continue;
        const auto parsed = parse_mqtt_uri(*server);
        if (!parsed) {
            sink.error(server, parsed.error);
            continue;
        }
        if (parsed.value->scheme != "tcp" && parsed.value->scheme != "ssl") {
            sink.error(server, "'" + *server + "': a Sparkplug server is tcp:// or ssl://; expected e.g. "
                                               "tcp://broker:1883");
            continue;
        }
        any_tls = any_tls || parsed.value->tls();
    }
    return any_tls;
}

/// Every configured device is a Sparkplug device: its name is a device_id.
void check_device_names(const RawConfig& raw, DiagnosticSink& sink) {
    for (const auto& line : raw.lines.items) {
        for (const auto& device : line.devices.items) check_id(sink, device.name, "device_id (the device name)");
    }
    for (const auto& upstream : raw.upstreams.items) {
        for (const auto& unit : upstream.units.items) check_id(sink, unit.name, "device_id (the unit name)");
    }
}

void check_state_dir(const Field<std::string>& field, const std::filesystem::path& base_dir, DiagnosticSink& sink) {
    if (!field.has_value()) return;
    if (field->empty()) {
        sink.error(field, "is empty; expected a directory, or no state_dir ($STATE_DIRECTORY, else /var/lib/fieldbridge)");
        return;
    }
    const auto path = resolve_path(base_dir, *field);
    std::error_code ec;
    if (!std::filesystem::is_directory(path, ec)) {
        sink.error(field, path.string() + " is not an existing directory; expected the directory that keeps the "
                                          "Sparkplug bdSeq (create it, writable by the service user)");
    }
}

}  // namespace

void validate_sparkplug(const RawConfig& raw, const std::filesystem::path& base_dir, DiagnosticSink& sink) {
    const RawSparkplug& sparkplug = raw.sparkplug;
    if (!sparkplug.ok()) {
        return;
    }
    const bool tls_server = check_servers(sparkplug, sink);
    check_mqtt_client_id(sparkplug.client_id, sink);
    if (sparkplug.client_id.has_value() && raw.mqtt.ok() && raw.mqtt.client_id.has_value() &&
        *sparkplug.client_id == *raw.mqtt.client_id) {
        sink.error(sparkplug.client_id, "is mqtt.client_id too; expected another one (a broker disconnects the "
                                        "older of two clients with the same id)");
    }
    if (require(sink, sparkplug.group_id, "the Sparkplug group_id, e.g. plant1")) {
        check_id(sink, sparkplug.group_id, "group_id");
    }
    check_id(sink, sparkplug.edge_node_id, "edge_node_id");
    if (sparkplug.edge_node_id.absent() && raw.gateway.id.has_value()) {
        if (const auto problem = sparkplug_id_problem(*raw.gateway.id)) {
            sink.error(raw.gateway.id, "'" + *raw.gateway.id + "' is the Sparkplug edge_node_id too (sparkplug."
                                       "edge_node_id is not set), and it " + *problem + "; expected sparkplug.edge_node_id");
        }
    }
    check_id(sink, sparkplug.primary_host_id, "primary_host_id");
    check_device_names(raw, sink);
    check_mqtt_credentials({sparkplug.username, sparkplug.password, sparkplug.password_file, ""},
                           MqttVersion::v3_1_1, base_dir, sink);
    check_mqtt_tls(sparkplug.tls, tls_server || sparkplug.servers.items.empty(),
                   "TLS settings need an ssl:// server, but every server is tcp://; expected e.g. servers: "
                   "[ssl://broker:8883] (or remove tls)",
                   base_dir, sink);
    if (check_range(sink, sparkplug.keep_alive, SparkplugConfig::keep_alive_range) &&
        sparkplug.keep_alive->count() % 1000 != 0) {
        sink.error(sparkplug.keep_alive, format_duration(*sparkplug.keep_alive) +
                                             " is not whole seconds; MQTT carries the keep alive in seconds");
    }
    check_range(sink, sparkplug.offline_buffer.max_messages, SparkplugOfflineBufferConfig::max_messages_range);
    check_range(sink, sparkplug.offline_buffer.max_bytes, SparkplugOfflineBufferConfig::max_bytes_range);
    check_state_dir(sparkplug.state_dir, base_dir, sink);
}

}  // namespace fieldbridge::config
