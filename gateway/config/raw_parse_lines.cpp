#include "config/raw_parse.hpp"

namespace fieldbridge::config {

namespace {

RawRs485 parse_rs485(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref, {"enabled", "rts_on_send", "rts_after_send", "delay_before_send", "delay_after_send"},
                        sink);
    RawRs485 raw;
    map.fill(raw);
    raw.enabled = read_bool(map, "enabled");
    raw.rts_on_send = read_bool(map, "rts_on_send");
    raw.rts_after_send = read_bool(map, "rts_after_send");
    raw.delay_before_send = read_duration(map, "delay_before_send");
    raw.delay_after_send = read_duration(map, "delay_after_send");
    return raw;
}

RawPoll parse_poll(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref, {"fast", "slow", "motion"}, sink);
    RawPoll raw;
    map.fill(raw);
    raw.fast = read_duration(map, "fast");
    raw.slow = read_duration(map, "slow");
    raw.motion = read_duration(map, "motion");
    return raw;
}

}  // namespace

RawBlock parse_block(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref, {"table", "address", "count", "period", "writable"}, sink);
    RawBlock raw;
    map.fill(raw);
    raw.table = read_enum(map, "table", core::register_table_names);
    raw.address = read_int(map, "address");
    raw.count = read_int(map, "count");
    raw.period = read_duration(map, "period");
    raw.writable = read_bool(map, "writable");
    return raw;
}

namespace {

RawDevice parse_device(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref,
                        {"name", "type", "address", "unit_id", "max_age", "command_ttl", "delay_before_command",
                         "queue_limit", "request_gap", "first_request_delay", "poll", "allow_protected", "mqtt_commands", "word_order", "stroke", "blocks",
                         "period", "max_gap", "points", "alarms"},
                        sink);
    RawDevice raw;
    map.fill(raw);
    raw.name = read_string(map, "name");
    raw.type_name = read_string(map, "type");
    if (raw.type_name.has_value()) {
        // A built-in type's name; any other name is a device definition's, looked up
        // by resolve_definitions().
        if (const auto type = core::parse<DeviceType>(*raw.type_name)) {
            raw.type.value = *type;
        }
        raw.type.path = raw.type_name.path;
        raw.type.mark = raw.type_name.mark;
    } else {
        raw.type.path = raw.type_name.path;
        raw.type.mark = raw.type_name.mark;
        raw.type.invalid = raw.type_name.invalid;
    }
    raw.address = read_int(map, "address");
    raw.unit_id = read_int(map, "unit_id");
    raw.max_age = read_duration(map, "max_age");
    raw.command_ttl = read_duration(map, "command_ttl");
    raw.delay_before_command = read_duration(map, "delay_before_command");
    raw.queue_limit = read_int(map, "queue_limit");
    raw.request_gap = read_duration(map, "request_gap");
    raw.first_request_delay = read_duration(map, "first_request_delay");
    raw.poll = parse_poll(map.child("poll"), sink);
    raw.allow_protected = read_bool(map, "allow_protected");
    raw.mqtt_commands = read_bool(map, "mqtt_commands");
    raw.word_order = read_enum(map, "word_order", core::word_order_names);
    raw.stroke = read_int(map, "stroke");
    raw.blocks = read_seq<RawBlock>(map, "blocks", parse_block);
    raw.period = read_duration(map, "period");
    raw.max_gap = read_int(map, "max_gap");
    raw.points = parse_points(map, "points");
    raw.alarms = parse_alarms(map, "alarms");
    return raw;
}

RawLine parse_line(const NodeRef& ref, DiagnosticSink& sink) {
    const MapReader map(ref,
                        {"name", "port", "baud", "parity", "data_bits", "stop_bits", "rs485", "local_echo",
                         "response_timeout", "byte_timeout", "turnaround", "broadcast_delay", "precise_timing", "request_gap", "tcp_frame_gap",
                         "connect_timeout", "reconnect_backoff", "read_retries", "offline_after",
                         "offline_backoff", "broadcast_unit", "broadcast_share", "devices"},
                        sink);
    RawLine raw;
    map.fill(raw);
    raw.name = read_string(map, "name");
    raw.port = read_string(map, "port");
    raw.baud = read_int(map, "baud");
    raw.parity = read_enum(map, "parity", core::parity_names);
    raw.data_bits = read_int(map, "data_bits");
    raw.stop_bits = read_int(map, "stop_bits");
    raw.rs485 = parse_rs485(map.child("rs485"), sink);
    raw.local_echo = read_bool(map, "local_echo");
    raw.response_timeout = read_duration(map, "response_timeout");
    raw.byte_timeout = read_duration(map, "byte_timeout");
    raw.turnaround = read_duration(map, "turnaround");
    raw.broadcast_delay = read_duration(map, "broadcast_delay");
    raw.precise_timing = read_bool(map, "precise_timing");
    raw.request_gap = read_duration(map, "request_gap");
    raw.tcp_frame_gap = read_duration(map, "tcp_frame_gap");
    raw.connect_timeout = read_duration(map, "connect_timeout");
    raw.reconnect_backoff = parse_backoff(map.child("reconnect_backoff"), sink);
    raw.read_retries = read_int(map, "read_retries");
    raw.offline_after = read_int(map, "offline_after");
    raw.offline_backoff = parse_backoff(map.child("offline_backoff"), sink);
    raw.broadcast_unit = read_int(map, "broadcast_unit");
    raw.broadcast_share = read_int(map, "broadcast_share");
    raw.devices = read_seq<RawDevice>(map, "devices", parse_device);
    return raw;
}

}  // namespace

RawSeq<RawLine> parse_lines(const MapReader& root) { return read_seq<RawLine>(root, "lines", parse_line); }

}  // namespace fieldbridge::config
