#include "config/raw_parse.hpp"

#include "config/net_address.hpp"
#include "config/scalars.hpp"

namespace fieldbridge::config {

namespace {

RawGateway parse_gateway(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref, {"id", "log_level"}, sink);
    RawGateway raw;
    map.fill(raw);
    raw.id = read_string(map, "id");
    raw.log_level = read_enum(map, "log_level", core::log_level_names);
    return raw;
}

FieldList<Cidr> read_cidr_list(const MapReader& map, std::string_view key) {
    return read_list<Cidr>(map, key, "networks such as 10.0.0.0/8", parse_cidr);
}

FieldList<std::int64_t> read_int_list(const MapReader& map, std::string_view key) {
    return read_list<std::int64_t>(map, key, "integers", parse_integer);
}

RawRule parse_rule(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref, {"clients", "units", "functions", "registers", "action"}, sink);
    RawRule raw;
    map.fill(raw);
    raw.clients = read_cidr_list(map, "clients");
    raw.units = read_int_list(map, "units");
    raw.functions = read_int_list(map, "functions");
    const MapReader registers(map.child("registers"), {"from", "to"}, sink);
    registers.fill(raw.registers);
    raw.registers.from = read_int(registers, "from");
    raw.registers.to = read_int(registers, "to");
    raw.action = read_enum<RuleAction>(map, "action", {{"allow", RuleAction::allow}, {"deny", RuleAction::deny}});
    return raw;
}

RawModbusTcp parse_modbus_tcp(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref,
                        {"listen", "max_connections", "idle_timeout", "frame_timeout", "max_connections_per_client",
                         "allow", "rules"},
                        sink);
    RawModbusTcp raw;
    map.fill(raw);
    raw.listen = read_list<ListenAddress>(map, "listen", "addresses such as 0.0.0.0:502", parse_listen_address);
    raw.max_connections = read_int(map, "max_connections");
    raw.idle_timeout = read_duration(map, "idle_timeout");
    raw.frame_timeout = read_duration(map, "frame_timeout");
    raw.max_connections_per_client = read_int(map, "max_connections_per_client");
    raw.allow = read_cidr_list(map, "allow");
    raw.rules = read_seq<RawRule>(map, "rules", parse_rule);
    return raw;
}

RawUpstreamUnit parse_upstream_unit(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref, {"unit_id", "upstream_unit", "name"}, sink);
    RawUpstreamUnit raw;
    map.fill(raw);
    raw.unit_id = read_int(map, "unit_id");
    raw.upstream_unit = read_int(map, "upstream_unit");
    raw.name = read_string(map, "name");
    return raw;
}

RawUpstream parse_upstream(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref,
                        {"name", "host", "port", "connect_timeout", "response_timeout", "reconnect_backoff",
                         "poll_period", "command_ttl", "queue_limit", "sequence_max_hold", "units"},
                        sink);
    RawUpstream raw;
    map.fill(raw);
    raw.name = read_string(map, "name");
    raw.host = read_string(map, "host");
    raw.port = read_int(map, "port");
    raw.connect_timeout = read_duration(map, "connect_timeout");
    raw.response_timeout = read_duration(map, "response_timeout");
    raw.reconnect_backoff = parse_backoff(map.child("reconnect_backoff"), sink);
    raw.poll_period = read_duration(map, "poll_period");
    raw.sequence_max_hold = read_duration(map, "sequence_max_hold");
    raw.command_ttl = read_duration(map, "command_ttl");
    raw.queue_limit = read_int(map, "queue_limit");
    raw.units = read_seq<RawUpstreamUnit>(map, "units", parse_upstream_unit);
    return raw;
}

RawTls parse_tls(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref, {"ca_file", "cert_file", "key_file", "verify"}, sink);
    RawTls raw;
    map.fill(raw);
    raw.ca_file = read_string(map, "ca_file");
    raw.cert_file = read_string(map, "cert_file");
    raw.key_file = read_string(map, "key_file");
    raw.verify = read_bool(map, "verify");
    return raw;
}

RawDeadband parse_deadband(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref, sink);  // keys are state field names
    RawDeadband raw;
    map.fill(raw);
    for (const auto& entry : map.entries()) {
        Field<std::string> name;
        name.value = entry.key;
        name.path = entry.value.path;
        name.mark = entry.key_mark;
        Field<double> threshold = read_scalar<double>(entry.value, sink, "a number", parse_number);
        raw.entries.emplace_back(std::move(name), std::move(threshold));
    }
    return raw;
}

/// A text or a list of texts: a single one becomes a list of one, at the key's own path.
FieldList<std::string> read_one_or_list(const MapReader& map, std::string_view key, std::string_view what) {
    const NodeRef ref = map.child(key);
    if (ref.node && ref.node->IsSequence()) {
        return read_list<std::string>(map, key, what,
                                      [](std::string_view text) { return Parsed<std::string>::ok(std::string(text)); });
    }
    FieldList<std::string> list;
    list.path = ref.path;
    list.mark = ref.mark;
    Field<std::string> one = read_string(map, key);
    if (one.absent()) return list;
    list.state = one.invalid ? RawNode::State::invalid : RawNode::State::ok;
    list.items.push_back(std::move(one));
    return list;
}

RawMqtt parse_mqtt(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref,
                        {"enabled", "uri", "client_id", "username", "password", "password_file", "tls", "qos",
                         "keep_alive", "clean_session", "version", "prefix", "heartbeat", "min_interval", "deadband",
                         "diag_period", "reconnect_backoff", "max_command_bytes", "max_command_id_length",
                         "max_queued_commands", "max_queued_command_bytes", "outbox_max_bytes",
                         "outbox_max_messages"},
                        sink);
    RawMqtt raw;
    map.fill(raw);
    raw.enabled = read_bool(map, "enabled");
    raw.uri = read_one_or_list(map, "uri", "broker URIs (tcp://host:1883, ssl://host:8883)");
    raw.client_id = read_string(map, "client_id");
    raw.username = read_string(map, "username");
    raw.password = read_string(map, "password");
    raw.password_file = read_string(map, "password_file");
    raw.tls = parse_tls(map.child("tls"), sink);
    raw.qos = read_int(map, "qos");
    raw.keep_alive = read_duration(map, "keep_alive");
    raw.clean_session = read_bool(map, "clean_session");
    raw.version = read_enum<MqttVersion>(map, "version", {{"3.1.1", MqttVersion::v3_1_1}, {"5", MqttVersion::v5}});
    raw.prefix = read_string(map, "prefix");
    raw.heartbeat = read_duration(map, "heartbeat");
    raw.min_interval = read_duration(map, "min_interval");
    raw.deadband = parse_deadband(map.child("deadband"), sink);
    raw.diag_period = read_duration(map, "diag_period");
    raw.reconnect_backoff = parse_backoff(map.child("reconnect_backoff"), sink);
    raw.max_command_bytes = read_int(map, "max_command_bytes");
    raw.max_command_id_length = read_int(map, "max_command_id_length");
    raw.max_queued_commands = read_int(map, "max_queued_commands");
    raw.max_queued_command_bytes = read_int(map, "max_queued_command_bytes");
    raw.outbox_max_bytes = read_int(map, "outbox_max_bytes");
    raw.outbox_max_messages = read_int(map, "outbox_max_messages");
    return raw;
}

RawOfflineBuffer parse_offline_buffer(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref, {"max_messages", "max_bytes"}, sink);
    RawOfflineBuffer raw;
    map.fill(raw);
    raw.max_messages = read_int(map, "max_messages");
    raw.max_bytes = read_int(map, "max_bytes");
    return raw;
}

RawSparkplug parse_sparkplug(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref,
                        {"servers", "client_id", "group_id", "edge_node_id", "primary_host_id", "username",
                         "password", "password_file", "tls", "keep_alive", "aliases", "offline_buffer", "state_dir"},
                        sink);
    RawSparkplug raw;
    map.fill(raw);
    raw.servers = read_list<std::string>(map, "servers", "server URIs (tcp://host:1883, ssl://host:8883)",
                                         [](std::string_view text) { return Parsed<std::string>::ok(std::string(text)); });
    raw.client_id = read_string(map, "client_id");
    raw.group_id = read_string(map, "group_id");
    raw.edge_node_id = read_string(map, "edge_node_id");
    raw.primary_host_id = read_string(map, "primary_host_id");
    raw.username = read_string(map, "username");
    raw.password = read_string(map, "password");
    raw.password_file = read_string(map, "password_file");
    raw.tls = parse_tls(map.child("tls"), sink);
    raw.keep_alive = read_duration(map, "keep_alive");
    raw.aliases = read_bool(map, "aliases");
    raw.offline_buffer = parse_offline_buffer(map.child("offline_buffer"), sink);
    raw.state_dir = read_string(map, "state_dir");
    return raw;
}

RawMetricsHttp parse_metrics_http(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref, {"listen"}, sink);
    RawMetricsHttp raw;
    map.fill(raw);
    raw.listen = read_listen_address(map, "listen");
    return raw;
}

}  // namespace

RawBackoff parse_backoff(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref, {"initial", "max"}, sink);
    RawBackoff raw;
    map.fill(raw);
    raw.initial = read_duration(map, "initial");
    raw.max = read_duration(map, "max");
    return raw;
}

RawConfig parse_raw(const YAML::Node& root, DiagnosticSink& sink) {
    const NodeRef root_ref{root, "", to_mark(root.Mark(), Mark{1, 1})};
    const MapReader map(root_ref, {"gateway", "modbus_tcp", "lines", "upstreams", "mqtt", "metrics_http", "sparkplug",
                                          "definitions"},
                        sink, true);
    RawConfig raw;
    map.fill(raw);
    raw.gateway = parse_gateway(map.child("gateway"), sink);
    raw.modbus_tcp = parse_modbus_tcp(map.child("modbus_tcp"), sink);
    raw.lines = parse_lines(map);
    raw.upstreams = read_seq<RawUpstream>(map, "upstreams", parse_upstream);
    raw.mqtt = parse_mqtt(map.child("mqtt"), sink);
    raw.sparkplug = parse_sparkplug(map.child("sparkplug"), sink);
    raw.metrics_http = parse_metrics_http(map.child("metrics_http"), sink);
    raw.definitions = read_list<std::string>(map, "definitions", "directories of device definition files",
                                             [](std::string_view text) { return Parsed<std::string>::ok(std::string(text)); });
    return raw;
}

}  // namespace fieldbridge::config
