#include <algorithm>
#include <fstream>
#include <system_error>

#include "config/mqtt_uri.hpp"
#include "config/validate.hpp"

namespace fieldbridge::config {

namespace {

constexpr std::string_view relative_note = " (relative paths are taken from the config file's directory)";

/// Reports a file that is set but does not exist. Returns true when it exists.
bool check_file(const Field<std::string>& field, const std::filesystem::path& base_dir, DiagnosticSink& sink) {
    if (!field.has_value() || field->empty()) {
        return false;
    }
    const auto path = resolve_path(base_dir, *field);
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) {
        sink.error(field, "file not found: " + path.string() + std::string(relative_note) + "; expected an existing file");
        return false;
    }
    if (!std::filesystem::is_regular_file(path, ec)) {
        sink.error(field, path.string() + " is not a regular file; expected a file");
        return false;
    }
    return true;
}

}  // namespace

void check_mqtt_credentials(const MqttCredentialFields& fields, MqttVersion version,
                            const std::filesystem::path& base_dir, DiagnosticSink& sink) {
    const bool has_password = fields.password.has_value() && !fields.password->empty();
    const bool has_password_file = fields.password_file.has_value() && !fields.password_file->empty();
    if (has_password && has_password_file) {
        sink.error(fields.password_file, "password and password_file are both set; expected only one of them "
                                         "(password_file keeps the secret out of this file)");
    }
    if (check_file(fields.password_file, base_dir, sink)) {
        const auto path = resolve_path(base_dir, *fields.password_file);
        std::ifstream in(path);
        if (!in) {
            sink.error(fields.password_file, "cannot read " + path.string() +
                                                 "; check that the service user may read it");
        }
    }
    const bool has_username = fields.username.has_value() && !fields.username->empty();
    if ((has_password || has_password_file) && !has_username && version == MqttVersion::v3_1_1) {
        // MQTT 3.1.1 section 3.1.2.9: a password without a user name is not allowed.
        const auto& culprit = has_password ? fields.password : fields.password_file;
        sink.error(culprit, "a password needs a username in MQTT 3.1.1; expected username to be set too" +
                                std::string(fields.version_hint));
    }
}

void check_mqtt_tls(const RawTls& tls, bool tls_uri, std::string_view uri_hint, const std::filesystem::path& base_dir,
                    DiagnosticSink& sink) {
    if (!tls.ok()) {
        return;
    }
    const auto set = [](const Field<std::string>& f) { return f.has_value() && !f->empty(); };
    check_file(tls.ca_file, base_dir, sink);
    check_file(tls.cert_file, base_dir, sink);
    check_file(tls.key_file, base_dir, sink);
    if (set(tls.key_file) && !set(tls.cert_file)) {
        sink.error(tls.key_file, "key_file is set without cert_file; expected the client certificate in cert_file");
    }
    const bool tls_settings = set(tls.ca_file) || set(tls.cert_file) || set(tls.key_file) ||
                              (tls.verify.has_value() && !*tls.verify);
    if (tls_settings && !tls_uri) {
        sink.error(tls, std::string(uri_hint));
    }
}

void check_mqtt_client_id(const Field<std::string>& client_id, DiagnosticSink& sink) {
    if (client_id.has_value() && !client_id->empty()) {
        const auto& id = *client_id;
        const bool printable = std::all_of(id.begin(), id.end(), [](char c) { return c > ' ' && c < 127; });
        if (!printable || id.size() > MqttConfig::max_client_id_length) {
            sink.error(client_id, "'" + id + "' is not a usable client id; expected 1.." +
                                      std::to_string(MqttConfig::max_client_id_length) +
                                      " printable characters without spaces");
        }
    }
}

namespace {

void check_topics(const RawMqtt& mqtt, DiagnosticSink& sink) {
    check_mqtt_client_id(mqtt.client_id, sink);
    if (mqtt.prefix.has_value() && !mqtt.prefix->empty()) {
        const auto& prefix = *mqtt.prefix;
        std::string problem;
        if (prefix.find_first_of("+#") != std::string::npos) {
            problem = "contains a wildcard (+ or #)";
        } else if (prefix.front() == '/' || prefix.back() == '/') {
            problem = "starts or ends with /";
        } else if (prefix.find("//") != std::string::npos) {
            problem = "has an empty topic level (//)";
        } else if (prefix.front() == '$') {
            problem = "starts with $ (reserved for the broker, MQTT 3.1.1 section 4.7.2)";
        } else if (prefix.size() > MqttConfig::max_prefix_length) {
            problem = "is longer than " + std::to_string(MqttConfig::max_prefix_length) + " characters";
        } else if (std::any_of(prefix.begin(), prefix.end(), [](char c) { return static_cast<unsigned char>(c) < 0x20; })) {
            problem = "contains control characters";
        }
        if (!problem.empty()) {
            sink.error(mqtt.prefix, "'" + prefix + "' " + problem + "; expected topic levels such as plant/cell-7");
        }
    }
    for (const auto& [name, threshold] : mqtt.deadband.entries) {
        const auto& field = *name;
        const bool valid_name = !field.empty() && !(field.front() >= '0' && field.front() <= '9') &&
                                std::all_of(field.begin(), field.end(), [](char c) {
                                    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') ||
                                           (c >= '0' && c <= '9') || c == '_';
                                });
        if (!valid_name) {
            sink.error(name, "'" + field + "' is not a state field name; expected e.g. position_mm");
        }
        if (threshold.has_value() && *threshold < 0.0) {
            sink.error(threshold, "is negative; expected a threshold >= 0");
        }
    }
}

}  // namespace

void validate_mqtt(const RawMqtt& mqtt, const std::filesystem::path& base_dir, DiagnosticSink& sink) {
    if (!mqtt.ok()) {
        return;
    }
    std::optional<MqttUri> uri = parse_mqtt_uri(MqttConfig{}.uris.front()).value;
    if (mqtt.uri.ok() && mqtt.uri.items.empty()) {
        sink.error(mqtt.uri, "the list is empty; expected at least one broker, e.g. tcp://broker:1883");
    }
    std::optional<MqttUri> first;
    for (const auto& item : mqtt.uri.items) {
        if (!item.has_value()) continue;
        auto parsed = parse_mqtt_uri(*item);
        if (!parsed) {
            sink.error(item, std::move(parsed.error));
            uri.reset();  // no TLS verdict on a URI that does not parse
            continue;
        }
        if (!first) {
            first = parsed.value;
        } else if (parsed.value->tls() != first->tls()) {
            // One client, one TLS set-up: the brokers of a list all use TLS or none does.
            sink.error(item, "'" + *item + "' " + (parsed.value->tls() ? "uses" : "does not use") +
                                 " TLS and the first URI " + (first->tls() ? "does" : "does not") +
                                 "; expected every URI of the list with TLS (ssl://, wss://) or none");
        }
    }
    if (first) uri = std::move(first);
    check_mqtt_credentials({mqtt.username, mqtt.password, mqtt.password_file, " (or version: \"5\")"},
                           mqtt.version.value_or(MqttConfig{}.version), base_dir, sink);
    check_mqtt_tls(mqtt.tls, !uri || uri->tls(),
                   "TLS settings need an ssl:// or wss:// uri, but the uri is " + (uri ? uri->scheme : std::string("?")) +
                       "://...; expected uri: ssl://host:8883 (or remove tls)",
                   base_dir, sink);
    check_topics(mqtt, sink);
    check_range(sink, mqtt.qos, MqttConfig::qos_range);
    if (check_range(sink, mqtt.keep_alive, MqttConfig::keep_alive_range) && mqtt.keep_alive->count() % 1000 != 0) {
        // MQTT 3.1.1 section 3.1.2.10: the keep alive is a number of seconds.
        sink.error(mqtt.keep_alive, format_duration(*mqtt.keep_alive) +
                                        " is not whole seconds; MQTT carries the keep alive in seconds");
    }
    const bool heartbeat_ok = check_range(sink, mqtt.heartbeat, MqttConfig::heartbeat_range) || mqtt.heartbeat.absent();
    const bool interval_ok =
        check_range(sink, mqtt.min_interval, MqttConfig::min_interval_range) || mqtt.min_interval.absent();
    if (heartbeat_ok && interval_ok) {
        const auto heartbeat = mqtt.heartbeat.value_or(MqttConfig{}.heartbeat);
        const auto min_interval = mqtt.min_interval.value_or(MqttConfig{}.min_interval);
        if (heartbeat < min_interval) {
            const auto& culprit = mqtt.heartbeat.has_value() ? mqtt.heartbeat : mqtt.min_interval;
            sink.error(culprit, "heartbeat (" + format_duration(heartbeat) + ") is shorter than min_interval (" +
                                    format_duration(min_interval) + "); expected heartbeat >= min_interval");
        }
    }
    check_range(sink, mqtt.diag_period, MqttConfig::diag_period_range);
    check_range(sink, mqtt.max_command_bytes, MqttConfig::max_command_bytes_range);
    check_range(sink, mqtt.max_command_id_length, MqttConfig::max_command_id_length_range);
    check_range(sink, mqtt.max_queued_commands, MqttConfig::max_queued_commands_range);
    check_range(sink, mqtt.max_queued_command_bytes, MqttConfig::max_queued_command_bytes_range);
    check_range(sink, mqtt.outbox_max_bytes, MqttConfig::outbox_max_bytes_range);
    check_range(sink, mqtt.outbox_max_messages, MqttConfig::outbox_max_messages_range);
    check_backoff(sink, mqtt.reconnect_backoff, MqttConfig{}.reconnect_backoff);
}

}  // namespace fieldbridge::config
