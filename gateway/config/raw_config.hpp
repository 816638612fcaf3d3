#pragma once
/// @file raw_config.hpp
/// Step 1 of loading: the configuration as written, every value converted to its
/// type but not yet checked against limits, each with its key path and position.
/// Absent values stay empty here; defaults are applied only when building Config.
/// Internal to the config layer.

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "config/config.hpp"
#include "core/register_def.hpp"

namespace fieldbridge::config {

/// A 1-based position in the file.
struct Mark {
    int line = 0;
    int column = 0;
};

/// A map or a list node.
struct RawNode {
    enum class State { absent, invalid, ok };  ///< invalid: present but of the wrong kind (reported)
    State state = State::absent;
    std::string path;  ///< e.g. "lines[0].devices[2]"; "" for the document root
    Mark mark;         ///< of the node; of the enclosing map when absent

    [[nodiscard]] bool ok() const noexcept { return state == State::ok; }
    [[nodiscard]] bool absent() const noexcept { return state == State::absent; }
};

/// One scalar value. `value` is empty when the key is absent, or present but not
/// convertible (then a diagnostic was already reported and `invalid` is set).
template <class T>
struct Field {
    std::optional<T> value;
    std::string path;  ///< full key path
    Mark mark;         ///< of the value; of the enclosing map when absent
    bool invalid = false;

    [[nodiscard]] bool has_value() const noexcept { return value.has_value(); }
    [[nodiscard]] bool absent() const noexcept { return !value && !invalid; }
    [[nodiscard]] const T& operator*() const { return *value; }
    [[nodiscard]] const T* operator->() const { return &*value; }
    [[nodiscard]] T value_or(T fallback) const { return value ? *value : std::move(fallback); }
};

/// A list of scalars.
template <class T>
struct FieldList : RawNode {
    std::vector<Field<T>> items;
};

/// A list of maps.
template <class T>
struct RawSeq : RawNode {
    std::vector<T> items;
};

struct RawBackoff : RawNode {
    Field<std::chrono::milliseconds> initial;
    Field<std::chrono::milliseconds> max;
};

struct RawGateway : RawNode {
    Field<std::string> id;
    Field<LogLevel> log_level;
};

struct RawRegisterRange : RawNode {
    Field<std::int64_t> from;
    Field<std::int64_t> to;
};

struct RawRule : RawNode {
    FieldList<Cidr> clients;
    FieldList<std::int64_t> units;
    FieldList<std::int64_t> functions;
    RawRegisterRange registers;
    Field<RuleAction> action;
};

struct RawModbusTcp : RawNode {
    FieldList<ListenAddress> listen;
    Field<std::int64_t> max_connections;
    Field<std::chrono::milliseconds> idle_timeout;
    Field<std::chrono::milliseconds> frame_timeout;
    Field<std::int64_t> max_connections_per_client;
    FieldList<Cidr> allow;
    RawSeq<RawRule> rules;
};

struct RawRs485 : RawNode {
    Field<bool> enabled;
    Field<bool> rts_on_send;
    Field<bool> rts_after_send;
    Field<std::chrono::milliseconds> delay_before_send;
    Field<std::chrono::milliseconds> delay_after_send;
};

struct RawPoll : RawNode {
    Field<std::chrono::milliseconds> fast;
    Field<std::chrono::milliseconds> slow;
    Field<std::chrono::milliseconds> motion;
};

struct RawBlock : RawNode {
    Field<RegisterTable> table;
    Field<std::int64_t> address;
    Field<std::int64_t> count;
    Field<std::chrono::milliseconds> period;
    Field<bool> writable;
};

/// `enum:` of a point: raw value -> label, each with its position.
struct RawEnum : RawNode {
    std::vector<std::pair<Field<std::int64_t>, Field<std::string>>> entries;
};

/// One point (inline under a device, or in a device definition file).
struct RawPoint : RawNode {
    Field<std::string> name;
    Field<RegisterTable> table;
    Field<std::int64_t> address;
    Field<core::PointType> type;
    Field<std::int64_t> bit;
    Field<std::int64_t> count;
    Field<WordOrder> word_order;
    Field<core::ByteOrder> byte_order;
    Field<double> scale;
    Field<double> offset;
    Field<std::string> unit;
    RawEnum labels;
    Field<std::string> enum_other;
    Field<bool> enum_code;
    Field<bool> writable;
    Field<double> min;
    Field<double> max;
    Field<std::chrono::milliseconds> period;
    Field<double> deadband;
    Field<bool> invert;
    Field<core::PointFormat> format;
    Field<std::string> format_text;  ///< format `text`: the template, at the mark of format:
};

struct RawAlarm : RawNode {
    Field<std::string> name;
    Field<std::string> point;
    Field<double> above;
    Field<double> below;
    Field<std::string> equals;  ///< a number, or an enum label of the point
    Field<std::string> not_equals;
    Field<std::int64_t> bit;
    Field<double> hysteresis;
    Field<core::AlarmSeverity> severity;
    Field<std::string> text;
    Field<std::string> source;
};

struct RawIdentify : RawNode {
    Field<RegisterTable> table;
    Field<std::int64_t> address;
    Field<std::int64_t> count;
    FieldList<std::int64_t> expect;
};

/// One row of a built-in type's `registers:` (core/register_def.hpp).
struct RawRegister : RawNode {
    Field<std::string> name;
    Field<RegisterTable> table;
    Field<std::int64_t> address;
    Field<std::int64_t> width;
    Field<std::int64_t> count;
    Field<core::Access> access;
    Field<std::int64_t> min;
    Field<std::int64_t> max;
    Field<bool> motion;
    Field<bool> protect;  ///< `protected:`
    Field<bool> auto_reset;
    Field<std::int64_t> stop;
};

/// A device definition file (`<dir>/<name>.yaml`), as written. Its positions are
/// in `file`, not in the configuration.
struct RawDefinition : RawNode {
    std::string file;  ///< absolute path
    Field<std::string> name;
    Field<std::string> description;
    Field<WordOrder> word_order;
    Field<std::chrono::milliseconds> period;
    Field<std::int64_t> max_gap;
    RawSeq<RawPoint> points;
    RawSeq<RawAlarm> alarms;
    RawSeq<RawBlock> blocks;
    RawIdentify identify;
    Field<DeviceType> behaviour;     ///< the C++ hook of a built-in type
    RawSeq<RawRegister> registers;   ///< with `behaviour:` only
};

struct RawDevice : RawNode {
    Field<std::string> name;
    /// `type:` as written; `type` holds it when it names a built-in type, and
    /// DeviceType::modbus once a definition of that name was found (`definition`).
    Field<std::string> type_name;
    Field<DeviceType> type;
    Field<std::int64_t> address;
    Field<std::int64_t> unit_id;
    Field<std::chrono::milliseconds> max_age;
    Field<std::chrono::milliseconds> command_ttl;
    Field<std::chrono::milliseconds> delay_before_command;
    Field<std::int64_t> queue_limit;
    Field<std::chrono::milliseconds> request_gap;
    Field<std::chrono::milliseconds> first_request_delay;
    RawPoll poll;
    Field<bool> allow_protected;
    Field<bool> mqtt_commands;
    Field<WordOrder> word_order;
    Field<std::int64_t> stroke;
    RawSeq<RawBlock> blocks;
    Field<std::chrono::milliseconds> period;
    Field<std::int64_t> max_gap;
    RawSeq<RawPoint> points;
    RawSeq<RawAlarm> alarms;
    /// The definition `type_name` names; set by resolve_definitions() when found and
    /// free of problems.
    std::shared_ptr<const RawDefinition> definition;
};

struct RawLine : RawNode {
    Field<std::string> name;
    Field<std::string> port;
    Field<std::int64_t> baud;
    Field<Parity> parity;
    Field<std::int64_t> data_bits;
    Field<std::int64_t> stop_bits;
    RawRs485 rs485;
    Field<bool> local_echo;
    Field<std::chrono::milliseconds> response_timeout;
    Field<std::chrono::milliseconds> byte_timeout;
    Field<std::chrono::milliseconds> turnaround;
    Field<std::chrono::milliseconds> broadcast_delay;
    Field<bool> precise_timing;
    Field<std::chrono::milliseconds> request_gap;
    Field<std::chrono::milliseconds> tcp_frame_gap;
    Field<std::chrono::milliseconds> connect_timeout;
    RawBackoff reconnect_backoff;
    Field<std::int64_t> read_retries;
    Field<std::int64_t> offline_after;
    RawBackoff offline_backoff;
    Field<std::int64_t> broadcast_unit;
    Field<std::int64_t> broadcast_share;
    RawSeq<RawDevice> devices;
};

struct RawUpstreamUnit : RawNode {
    Field<std::int64_t> unit_id;
    Field<std::int64_t> upstream_unit;
    Field<std::string> name;
};

struct RawUpstream : RawNode {
    Field<std::string> name;
    Field<std::string> host;
    Field<std::int64_t> port;
    Field<std::chrono::milliseconds> connect_timeout;
    Field<std::chrono::milliseconds> response_timeout;
    RawBackoff reconnect_backoff;
    Field<std::chrono::milliseconds> poll_period;
    Field<std::chrono::milliseconds> sequence_max_hold;
    Field<std::chrono::milliseconds> command_ttl;
    Field<std::int64_t> queue_limit;
    RawSeq<RawUpstreamUnit> units;
};

struct RawTls : RawNode {
    Field<std::string> ca_file;
    Field<std::string> cert_file;
    Field<std::string> key_file;
    Field<bool> verify;
};

struct RawDeadband : RawNode {
    std::vector<std::pair<Field<std::string>, Field<double>>> entries;  ///< field name, threshold
};

struct RawMqtt : RawNode {
    Field<bool> enabled;
    FieldList<std::string> uri;  ///< one URI or a list; a single one is an item at path "mqtt.uri"
    Field<std::string> client_id;
    Field<std::string> username;
    Field<std::string> password;
    Field<std::string> password_file;
    RawTls tls;
    Field<std::int64_t> qos;
    Field<std::chrono::milliseconds> keep_alive;
    Field<bool> clean_session;
    Field<MqttVersion> version;
    Field<std::string> prefix;
    Field<std::chrono::milliseconds> heartbeat;
    Field<std::chrono::milliseconds> min_interval;
    RawDeadband deadband;
    Field<std::chrono::milliseconds> diag_period;
    RawBackoff reconnect_backoff;
    Field<std::int64_t> max_command_bytes;
    Field<std::int64_t> max_command_id_length;
    Field<std::int64_t> max_queued_commands;
    Field<std::int64_t> max_queued_command_bytes;
    Field<std::int64_t> outbox_max_bytes;
    Field<std::int64_t> outbox_max_messages;
};

struct RawOfflineBuffer : RawNode {
    Field<std::int64_t> max_messages;
    Field<std::int64_t> max_bytes;
};

struct RawSparkplug : RawNode {
    FieldList<std::string> servers;
    Field<std::string> client_id;
    Field<std::string> group_id;
    Field<std::string> edge_node_id;
    Field<std::string> primary_host_id;
    Field<std::string> username;
    Field<std::string> password;
    Field<std::string> password_file;
    RawTls tls;
    Field<std::chrono::milliseconds> keep_alive;
    Field<bool> aliases;
    RawOfflineBuffer offline_buffer;
    Field<std::string> state_dir;
};

struct RawMetricsHttp : RawNode {
    Field<ListenAddress> listen;
};

struct RawConfig : RawNode {
    RawGateway gateway;
    RawModbusTcp modbus_tcp;
    RawSeq<RawLine> lines;
    RawSeq<RawUpstream> upstreams;
    RawMqtt mqtt;
    RawSparkplug sparkplug;
    RawMetricsHttp metrics_http;
    FieldList<std::string> definitions;  ///< directories of device definition files
};

}  // namespace fieldbridge::config
