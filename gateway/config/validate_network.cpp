#include <algorithm>

#include "config/validate.hpp"

namespace fieldbridge::config {

namespace {

void check_gateway(const RawConfig& raw, DiagnosticSink& sink) {
    const RawGateway& gateway = raw.gateway;
    if (gateway.absent()) {
        sink.error(raw.mark, "gateway", "required section is missing; expected gateway: { id: <name> }");
        return;
    }
    if (!gateway.ok()) {
        return;
    }
    if (require(sink, gateway.id, "the gateway's name, e.g. cell-7 (it is part of the MQTT topics)") &&
        !is_valid_name(*gateway.id)) {
        sink.error(gateway.id, "'" + *gateway.id + "' is not a valid id; expected 1.." +
                                   std::to_string(max_name_length) +
                                   " characters from A-Z a-z 0-9 _ - (it is part of the MQTT topics)");
    }
}

void check_rule(const RawRule& rule, DiagnosticSink& sink) {
    require(sink, rule.action, "allow or deny");
    for (const auto& unit : rule.units.items) {
        check_range(sink, unit, Range<std::int64_t>{0, 255});
    }
    for (const auto& function : rule.functions.items) {
        check_range(sink, function, AccessRule::function_range);
    }
    const RawRegisterRange& registers = rule.registers;
    if (!registers.ok()) {
        return;
    }
    const bool from_ok = require(sink, registers.from, "the first register of the range, e.g. 0x0600") &&
                         check_range(sink, registers.from, Range<std::int64_t>{0, 0xFFFF});
    const bool to_ok = require(sink, registers.to, "the last register of the range (included), e.g. 0x0646") &&
                       check_range(sink, registers.to, Range<std::int64_t>{0, 0xFFFF});
    if (from_ok && to_ok && *registers.to < *registers.from) {
        sink.error(registers.to, hex16(*registers.to) + " is below from (" + hex16(*registers.from) +
                                     "); expected from <= to");
    }
}

void check_modbus_tcp(const RawModbusTcp& tcp, DiagnosticSink& sink) {
    if (!tcp.ok()) {
        return;
    }
    if (tcp.listen.ok() && tcp.listen.items.empty()) {
        sink.error(tcp.listen, "is empty; expected at least one address such as 0.0.0.0:502 (or remove the key for "
                               "the default)");
    }
    for (std::size_t i = 0; i < tcp.listen.items.size(); ++i) {
        const auto& item = tcp.listen.items[i];
        for (std::size_t j = 0; item.has_value() && j < i; ++j) {
            if (tcp.listen.items[j].has_value() && *tcp.listen.items[j] == *item) {
                sink.error(item, item->to_string() + " is listed twice; expected each address once");
            }
        }
    }
    check_range(sink, tcp.max_connections, ModbusTcpConfig::max_connections_range);
    check_range(sink, tcp.idle_timeout, ModbusTcpConfig::idle_timeout_range);
    check_range(sink, tcp.frame_timeout, ModbusTcpConfig::frame_timeout_range);
    check_range(sink, tcp.max_connections_per_client, ModbusTcpConfig::max_connections_per_client_range);
    for (const auto& rule : tcp.rules.items) {
        if (rule.ok()) {
            check_rule(rule, sink);
        }
    }
}

void check_upstream(const RawUpstream& upstream, DiagnosticSink& sink) {
    if (require(sink, upstream.name, "an upstream name such as r6-cell")) {
        check_name(sink, upstream.name);
    }
    if (require(sink, upstream.host, "the host name or IP address of the Modbus TCP server") &&
        !is_valid_host(*upstream.host)) {
        sink.error(upstream.host, "'" + *upstream.host +
                                      "' is not a host name or IP address; expected e.g. 192.168.1.20, ::1 or "
                                      "r6.local (no port here: use port)");
    }
    check_range(sink, upstream.port, Range<std::int64_t>{1, 65535});
    check_range(sink, upstream.connect_timeout, UpstreamConfig::connect_timeout_range);
    const bool response_ok = check_range(sink, upstream.response_timeout, UpstreamConfig::response_timeout_range) ||
                             upstream.response_timeout.absent();
    check_backoff(sink, upstream.reconnect_backoff, UpstreamConfig{}.reconnect_backoff);
    check_range(sink, upstream.poll_period, UpstreamConfig::poll_period_range);
    check_range(sink, upstream.sequence_max_hold, UpstreamConfig::sequence_max_hold_range);
    if (check_range(sink, upstream.command_ttl, UpstreamConfig::command_ttl_range) && response_ok) {
        const auto response_timeout = upstream.response_timeout.value_or(UpstreamConfig{}.response_timeout);
        if (*upstream.command_ttl < response_timeout) {
            sink.error(upstream.command_ttl, format_duration(*upstream.command_ttl) +
                                                 " is shorter than response_timeout (" +
                                                 format_duration(response_timeout) +
                                                 "): a command waiting behind one unanswered request would always "
                                                 "expire; expected at least " + format_duration(response_timeout));
        }
    }
    check_range(sink, upstream.queue_limit, UpstreamConfig::queue_limit_range);
    if (upstream.units.absent() || (upstream.units.ok() && upstream.units.items.empty())) {
        sink.error(upstream.units, upstream.units.absent()
                                       ? "required key is missing; expected the unit IDs that reach this server, e.g. "
                                         "units: [{unit_id: 50, upstream_unit: 1, name: r6}]"
                                       : "is empty; expected at least one unit");
    }
    for (const auto& unit : upstream.units.items) {
        if (!unit.ok()) {
            continue;
        }
        if (require(sink, unit.unit_id, "the gateway's Modbus TCP unit ID for this server (1..247)")) {
            check_range(sink, unit.unit_id, unit_id_range);
        }
        check_range(sink, unit.upstream_unit, Range<std::int64_t>{0, 255});
        if (require(sink, unit.name, "the device name used in MQTT topics, e.g. r6")) {
            check_name(sink, unit.name);
        }
    }
}

void check_metrics(const RawConfig& raw, DiagnosticSink& sink) {
    const RawMetricsHttp& metrics = raw.metrics_http;
    if (!metrics.ok() || !metrics.listen.has_value()) {
        return;
    }
    const auto& listen = raw.modbus_tcp.listen;
    std::vector<ListenAddress> tcp_addresses;
    if (listen.absent()) {
        tcp_addresses = ModbusTcpConfig{}.listen;
    }
    for (const auto& item : listen.items) {
        if (item.has_value()) {
            tcp_addresses.push_back(*item);
        }
    }
    for (const auto& address : tcp_addresses) {
        const bool wildcard = address.host == "0.0.0.0" || address.host == "::" || metrics.listen->host == "0.0.0.0" ||
                              metrics.listen->host == "::";
        if (address.port == metrics.listen->port && (wildcard || address.host == metrics.listen->host)) {
            sink.error(metrics.listen, metrics.listen->to_string() + " collides with the Modbus TCP listener " +
                                           address.to_string() + "; expected another port");
            return;
        }
    }
}

}  // namespace

void validate_network(const RawConfig& raw, DiagnosticSink& sink) {
    check_gateway(raw, sink);
    check_modbus_tcp(raw.modbus_tcp, sink);
    for (const auto& upstream : raw.upstreams.items) {
        if (upstream.ok()) {
            check_upstream(upstream, sink);
        }
    }
    check_metrics(raw, sink);
}

}  // namespace fieldbridge::config
