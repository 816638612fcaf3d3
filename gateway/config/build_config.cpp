#include "config/build_config.hpp"

#include <cstdlib>
#include <fstream>
#include <iterator>

#include "config/build_points.hpp"
#include "config/validate.hpp"

namespace fieldbridge::config {

namespace {

template <class To>
[[nodiscard]] To narrow(const Field<std::int64_t>& field, To fallback) {
    return field.has_value() ? static_cast<To>(*field) : fallback;
}

template <class T>
void set(T& target, const Field<T>& field) {
    if (field.has_value()) {
        target = *field;
    }
}

[[nodiscard]] Backoff build_backoff(const RawBackoff& raw, Backoff defaults) {
    set(defaults.initial, raw.initial);
    set(defaults.max, raw.max);
    return defaults;
}

[[nodiscard]] std::string resolved_file(const Field<std::string>& field, const std::filesystem::path& base_dir) {
    if (!field.has_value() || field->empty()) {
        return {};
    }
    return resolve_path(base_dir, *field).string();
}

[[nodiscard]] ModbusTcpConfig build_modbus_tcp(const RawModbusTcp& raw) {
    ModbusTcpConfig tcp;
    if (raw.listen.ok()) {
        tcp.listen.clear();
        for (const auto& item : raw.listen.items) {
            tcp.listen.push_back(*item);
        }
    }
    tcp.max_connections = narrow<std::size_t>(raw.max_connections, tcp.max_connections);
    set(tcp.idle_timeout, raw.idle_timeout);
    set(tcp.frame_timeout, raw.frame_timeout);
    tcp.max_connections_per_client = narrow<std::size_t>(raw.max_connections_per_client, tcp.max_connections_per_client);
    for (const auto& item : raw.allow.items) {
        tcp.allow.push_back(*item);
    }
    for (const auto& raw_rule : raw.rules.items) {
        AccessRule rule;
        for (const auto& c : raw_rule.clients.items) {
            rule.clients.push_back(*c);
        }
        for (const auto& u : raw_rule.units.items) {
            rule.units.emplace_back(static_cast<std::uint8_t>(*u));
        }
        for (const auto& f : raw_rule.functions.items) {
            rule.functions.emplace_back(static_cast<std::uint8_t>(*f));
        }
        if (raw_rule.registers.ok()) {
            rule.registers = RegisterRange{static_cast<std::uint16_t>(*raw_rule.registers.from),
                                           static_cast<std::uint16_t>(*raw_rule.registers.to)};
        }
        rule.action = *raw_rule.action;
        tcp.rules.push_back(std::move(rule));
    }
    return tcp;
}

[[nodiscard]] DeviceConfig build_device(const RawDevice& raw) {
    DeviceConfig device;
    device.name = *raw.name;
    device.type = *raw.type;
    device.type_name = *raw.type_name;
    device.address = core::BusAddress{static_cast<std::uint8_t>(*raw.address)};
    device.unit_id = core::UnitId{static_cast<std::uint8_t>(*raw.unit_id)};
    set(device.max_age, raw.max_age);
    set(device.command_ttl, raw.command_ttl);
    set(device.delay_before_command, raw.delay_before_command);
    device.queue_limit = narrow<std::size_t>(raw.queue_limit, device.queue_limit);
    set(device.request_gap, raw.request_gap);
    set(device.first_request_delay, raw.first_request_delay);
    set(device.poll.fast, raw.poll.fast);
    set(device.poll.slow, raw.poll.slow);
    set(device.poll.motion, raw.poll.motion);
    set(device.allow_protected, raw.allow_protected);
    set(device.mqtt_commands, raw.mqtt_commands);
    set(device.word_order, raw.word_order);
    if (raw.stroke.has_value()) {
        device.stroke = static_cast<std::uint32_t>(*raw.stroke);
    }
    const RawDefinition* definition = raw.definition.get();
    if (device.type != DeviceType::modbus) {
        if (definition != nullptr) {  // a file replaces the compiled-in definition
            device.definition_file = definition->file;
            device.registers = build_registers(*definition);
            if (!definition->points.absent()) {
                device.builtin_state = build_point_model(definition, nullptr, point_defaults(definition, nullptr));
            }
        }
        return device;
    }
    const PointDefaults defaults = point_defaults(definition, &raw);
    device.word_order = defaults.word_order;
    device.period = defaults.period;
    if (definition != nullptr) {
        device.definition_file = definition->file;
        for (const auto& raw_block : definition->blocks.items) {
            device.blocks.push_back(build_block(raw_block, defaults.period));
        }
    }
    for (const auto& raw_block : raw.blocks.items) {
        device.blocks.push_back(build_block(raw_block, defaults.period));
    }
    device.points = build_point_model(definition, &raw, defaults);
    return device;
}

[[nodiscard]] LineConfig build_line(const RawLine& raw) {
    LineConfig line = framing_of(raw);  // name-less framing with defaults; validated values are in range
    line.name = *raw.name;
    line.port = *raw.port;
    if (is_tcp_port(line.port)) line.tcp = parse_tcp_port(line.port).value;  // validated
    set(line.rs485.enabled, raw.rs485.enabled);
    set(line.rs485.rts_on_send, raw.rs485.rts_on_send);
    set(line.rs485.rts_after_send, raw.rs485.rts_after_send);
    set(line.rs485.delay_before_send, raw.rs485.delay_before_send);
    set(line.rs485.delay_after_send, raw.rs485.delay_after_send);
    set(line.local_echo, raw.local_echo);
    set(line.response_timeout, raw.response_timeout);
    line.byte_timeout = raw.byte_timeout.value_or(default_byte_timeout(line));
    set(line.turnaround, raw.turnaround);
    set(line.broadcast_delay, raw.broadcast_delay);
    set(line.request_gap, raw.request_gap);
    line.precise_timing = raw.precise_timing.value_or(default_precise_timing(line));
    line.tcp_frame_gap = raw.tcp_frame_gap.value_or(default_byte_timeout(line));
    set(line.connect_timeout, raw.connect_timeout);
    line.reconnect_backoff = build_backoff(raw.reconnect_backoff, line.reconnect_backoff);
    line.read_retries = narrow<unsigned>(raw.read_retries, line.read_retries);
    line.offline_after = narrow<unsigned>(raw.offline_after, line.offline_after);
    line.offline_backoff = build_backoff(raw.offline_backoff, line.offline_backoff);
    if (raw.broadcast_unit.has_value()) {
        line.broadcast_unit = core::UnitId{static_cast<std::uint8_t>(*raw.broadcast_unit)};
    }
    line.broadcast_share = narrow<unsigned>(raw.broadcast_share, line.broadcast_share);
    for (const auto& device : raw.devices.items) {
        line.devices.push_back(build_device(device));
    }
    return line;
}

[[nodiscard]] UpstreamConfig build_upstream(const RawUpstream& raw) {
    UpstreamConfig upstream;
    upstream.name = *raw.name;
    upstream.host = *raw.host;
    upstream.port = narrow<std::uint16_t>(raw.port, upstream.port);
    set(upstream.connect_timeout, raw.connect_timeout);
    set(upstream.response_timeout, raw.response_timeout);
    upstream.reconnect_backoff = build_backoff(raw.reconnect_backoff, upstream.reconnect_backoff);
    set(upstream.poll_period, raw.poll_period);
    set(upstream.sequence_max_hold, raw.sequence_max_hold);
    set(upstream.command_ttl, raw.command_ttl);
    upstream.queue_limit = narrow<std::size_t>(raw.queue_limit, upstream.queue_limit);
    for (const auto& raw_unit : raw.units.items) {
        UpstreamUnitConfig unit;
        unit.unit_id = core::UnitId{static_cast<std::uint8_t>(*raw_unit.unit_id)};
        unit.upstream_unit = core::UnitId{narrow<std::uint8_t>(raw_unit.upstream_unit, unit.upstream_unit.value)};
        unit.name = *raw_unit.name;
        upstream.units.push_back(std::move(unit));
    }
    return upstream;
}

/// The password from @p path (when set) into @p password.
void read_password_file(const Field<std::string>& field, const std::string& path, std::string& password,
                        DiagnosticSink& sink) {
    if (path.empty()) {
        return;
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        sink.error(field, "cannot read " + path + "; check that the service user may read it");
    }
    std::string secret((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    // One trailing newline is what `echo secret > file` leaves: it is not part of
    // the password.
    if (!secret.empty() && secret.back() == '\n') {
        secret.pop_back();
        if (!secret.empty() && secret.back() == '\r') {
            secret.pop_back();
        }
    }
    password = std::move(secret);
}

[[nodiscard]] MqttTlsConfig build_tls(const RawTls& raw, const std::filesystem::path& base_dir) {
    MqttTlsConfig tls;
    tls.ca_file = resolved_file(raw.ca_file, base_dir);
    tls.cert_file = resolved_file(raw.cert_file, base_dir);
    tls.key_file = resolved_file(raw.key_file, base_dir);
    set(tls.verify, raw.verify);
    return tls;
}

/// $STATE_DIRECTORY (systemd: one or more paths separated by ':'; the first is ours),
/// else the packaged default.
[[nodiscard]] std::string default_state_dir() {
    const char* from_systemd = std::getenv("STATE_DIRECTORY");
    if (from_systemd == nullptr || *from_systemd == '\0') {
        return SparkplugConfig::default_state_dir;
    }
    const std::string_view list(from_systemd);
    return std::string(list.substr(0, list.find(':')));
}

[[nodiscard]] std::optional<SparkplugConfig> build_sparkplug(const RawSparkplug& raw, const std::string& gateway_id,
                                                             const std::filesystem::path& base_dir,
                                                             DiagnosticSink& sink) {
    if (!raw.ok()) {
        return std::nullopt;
    }
    SparkplugConfig sparkplug;
    for (const auto& server : raw.servers.items) {
        if (server.has_value()) {
            sparkplug.servers.push_back(*server);
        }
    }
    sparkplug.client_id = raw.client_id.value_or("");
    if (sparkplug.client_id.empty()) {
        sparkplug.client_id = "fieldbridge-" + gateway_id + "-sparkplug";
    }
    sparkplug.group_id = raw.group_id.value_or("");
    sparkplug.edge_node_id = raw.edge_node_id.value_or(gateway_id);
    set(sparkplug.primary_host_id, raw.primary_host_id);
    set(sparkplug.username, raw.username);
    set(sparkplug.password, raw.password);
    sparkplug.password_file = resolved_file(raw.password_file, base_dir);
    read_password_file(raw.password_file, sparkplug.password_file, sparkplug.password, sink);
    sparkplug.tls = build_tls(raw.tls, base_dir);
    set(sparkplug.keep_alive, raw.keep_alive);
    set(sparkplug.aliases, raw.aliases);
    auto& buffer = sparkplug.offline_buffer;
    buffer.max_messages = narrow<std::size_t>(raw.offline_buffer.max_messages, buffer.max_messages);
    buffer.max_bytes = narrow<std::size_t>(raw.offline_buffer.max_bytes, buffer.max_bytes);
    sparkplug.state_dir = raw.state_dir.has_value() ? resolve_path(base_dir, *raw.state_dir).string()
                                                    : default_state_dir();
    return sparkplug;
}

[[nodiscard]] MqttConfig build_mqtt(const RawMqtt& raw, const std::string& gateway_id,
                                    const std::filesystem::path& base_dir, DiagnosticSink& sink) {
    MqttConfig mqtt;
    mqtt.enabled = raw.ok() && raw.enabled.value_or(true);
    if (!raw.uri.items.empty()) {
        mqtt.uris.clear();
        for (const auto& item : raw.uri.items) {
            if (item.has_value()) mqtt.uris.push_back(*item);
        }
    }
    mqtt.client_id = raw.client_id.value_or("");
    if (mqtt.client_id.empty()) {
        mqtt.client_id = "fieldbridge-" + gateway_id;
    }
    set(mqtt.username, raw.username);
    set(mqtt.password, raw.password);
    mqtt.password_file = resolved_file(raw.password_file, base_dir);
    read_password_file(raw.password_file, mqtt.password_file, mqtt.password, sink);
    mqtt.tls = build_tls(raw.tls, base_dir);
    mqtt.qos = static_cast<int>(raw.qos.value_or(mqtt.qos));
    set(mqtt.keep_alive, raw.keep_alive);
    set(mqtt.clean_session, raw.clean_session);
    set(mqtt.version, raw.version);
    mqtt.prefix = raw.prefix.value_or("");
    if (mqtt.prefix.empty()) {
        mqtt.prefix = "fieldbridge/" + gateway_id;
    }
    set(mqtt.heartbeat, raw.heartbeat);
    set(mqtt.min_interval, raw.min_interval);
    for (const auto& [name, threshold] : raw.deadband.entries) {
        mqtt.deadband[*name] = *threshold;
    }
    set(mqtt.diag_period, raw.diag_period);
    mqtt.reconnect_backoff = build_backoff(raw.reconnect_backoff, mqtt.reconnect_backoff);
    mqtt.max_command_bytes = narrow<std::size_t>(raw.max_command_bytes, mqtt.max_command_bytes);
    mqtt.max_command_id_length = narrow<std::size_t>(raw.max_command_id_length, mqtt.max_command_id_length);
    mqtt.max_queued_commands = narrow<std::size_t>(raw.max_queued_commands, mqtt.max_queued_commands);
    mqtt.max_queued_command_bytes = narrow<std::size_t>(raw.max_queued_command_bytes, mqtt.max_queued_command_bytes);
    mqtt.outbox_max_bytes = narrow<std::size_t>(raw.outbox_max_bytes, mqtt.outbox_max_bytes);
    mqtt.outbox_max_messages = narrow<std::size_t>(raw.outbox_max_messages, mqtt.outbox_max_messages);
    return mqtt;
}

}  // namespace

Config build_config(const RawConfig& raw, const std::filesystem::path& base_dir, std::string source_file,
                    DiagnosticSink& sink) {
    Config config;
    config.source_file = std::move(source_file);
    config.gateway.id = *raw.gateway.id;
    set(config.gateway.log_level, raw.gateway.log_level);
    config.modbus_tcp = build_modbus_tcp(raw.modbus_tcp);
    for (const auto& line : raw.lines.items) {
        config.lines.push_back(build_line(line));
    }
    for (const auto& upstream : raw.upstreams.items) {
        config.upstreams.push_back(build_upstream(upstream));
    }
    config.mqtt = build_mqtt(raw.mqtt, config.gateway.id, base_dir, sink);
    config.sparkplug = build_sparkplug(raw.sparkplug, config.gateway.id, base_dir, sink);
    if (raw.metrics_http.ok()) {
        MetricsHttpConfig metrics;
        set(metrics.listen, raw.metrics_http.listen);
        config.metrics_http = metrics;
    }
    return config;
}

}  // namespace fieldbridge::config
