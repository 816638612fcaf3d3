#pragma once
/// @file config.hpp
/// The typed, immutable configuration of the gateway. Produced only by the loader
/// (config_loader.hpp) after validation, and shared read-only
/// (`std::shared_ptr<const Config>`); a reload builds a new one.
///
/// Every field carries its default beside it; every bounded field has its named
/// limits beside it (`*_range`), used by the validator and quoted in its messages.
/// The reference for operators is docs/configuration.md.

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "config/net_address.hpp"
#include "core/register_def.hpp"
#include "core/device_type.hpp"
#include "core/log_level.hpp"
#include "core/modbus_ids.hpp"
#include "core/parity.hpp"
#include "core/point.hpp"
#include "core/register_table.hpp"
#include "core/word_order.hpp"

namespace fieldbridge::config {

using std::chrono::milliseconds;
using std::chrono::seconds;

/// Inclusive bounds of a value.
template <class T>
struct Range {
    T min;
    T max;
    [[nodiscard]] constexpr bool contains(const T& v) const noexcept { return !(v < min) && !(max < v); }
};

// The enums the engine, scan and MQTT share are defined once, in core/ (with their
// one spelling table each); the configuration uses them under its own namespace.
using core::DeviceType;
using core::LogLevel;
using core::Parity;
using core::RegisterTable;
using core::to_string;
using core::WordOrder;

enum class RuleAction { allow, deny };
enum class MqttVersion { v3_1_1, v5 };

[[nodiscard]] std::string_view to_string(RuleAction action) noexcept;
/// "3.1.1" or "5".
[[nodiscard]] std::string_view to_string(MqttVersion version) noexcept;

/// Bus addresses a device of @p type may have (broadcast addresses excluded):
/// XEG 1-15 (seed 001 section 2.2: "15 IDs (1~F)"), EXCD203MB 1-254 (seed 002
/// section 5: slave 0x01-0xFE), WTEC 1-253 (seed 003: "01" to "253"), generic
/// Modbus 1-247 (Modbus over serial line V1.02 section 2.2).
[[nodiscard]] Range<std::uint8_t> address_range(DeviceType type) noexcept;
/// The broadcast address on the bus for @p type: 0xFF for EXCD203MB (seed 002
/// section 5), 0 for the others.
[[nodiscard]] core::BusAddress broadcast_address(DeviceType type) noexcept;
/// Types with 32-bit values spread over two registers, where `word_order` applies.
[[nodiscard]] bool has_register_pairs(DeviceType type) noexcept;

struct Backoff {
    milliseconds initial;
    milliseconds max;
    static constexpr Range<milliseconds> range{milliseconds{10}, std::chrono::hours{1}};
    bool operator==(const Backoff&) const = default;
};

/// Names of lines, devices and upstreams: [A-Za-z0-9_-], 1..64 characters (they are
/// MQTT topic levels and log fields).
inline constexpr std::size_t max_name_length = 64;
/// Modbus TCP unit IDs the gateway serves: 0 and 248-255 are reserved.
inline constexpr Range<std::int64_t> unit_id_range{1, 247};

struct GatewayConfig {
    std::string id;  ///< required; [A-Za-z0-9_-]{1,64}; part of MQTT topics and client id
    LogLevel log_level = LogLevel::info;
    bool operator==(const GatewayConfig&) const = default;
};

/// A register span, both ends included.
struct RegisterRange {
    std::uint16_t from = 0;
    std::uint16_t to = 0;
    bool operator==(const RegisterRange&) const = default;
};

/// One access rule. An empty list matches anything.
struct AccessRule {
    std::vector<Cidr> clients;
    std::vector<core::UnitId> units;            ///< must be configured unit IDs
    std::vector<core::FunctionCode> functions;  ///< function codes 1..127
    std::optional<RegisterRange> registers;
    RuleAction action = RuleAction::deny;  ///< required in the file

    static constexpr Range<std::int64_t> function_range{1, 127};

    /// A deny rule matches a request that touches any register of its range; an
    /// allow rule only a request that lies entirely inside it. A rule with a
    /// register range never matches a request without registers (e.g. FC07).
    [[nodiscard]] bool matches(const IpAddress& client, core::UnitId unit, core::FunctionCode function,
                               std::optional<RegisterRange> request) const noexcept;
    bool operator==(const AccessRule&) const = default;
};

struct ModbusTcpConfig {
    static constexpr std::uint16_t default_port = 502;
    std::vector<ListenAddress> listen{ListenAddress{"0.0.0.0", default_port}};
    std::size_t max_connections = 64;
    static constexpr Range<std::int64_t> max_connections_range{1, 1024};
    milliseconds idle_timeout = seconds{60};  ///< 0: idle connections are never closed
    static constexpr Range<milliseconds> idle_timeout_range{milliseconds{0}, std::chrono::hours{24}};
    /// A frame must be complete this long after its first byte arrived (slowloris).
    milliseconds frame_timeout = seconds{5};
    static constexpr Range<milliseconds> frame_timeout_range{milliseconds{10}, seconds{60}};
    /// Open connections from one client address; further ones are refused.
    std::size_t max_connections_per_client = 16;
    static constexpr Range<std::int64_t> max_connections_per_client_range{1, 1024};
    std::vector<Cidr> allow;  ///< empty: any client
    std::vector<AccessRule> rules;

    /// The allow-list (empty = any client).
    [[nodiscard]] bool client_allowed(const IpAddress& client) const noexcept;
    /// The first matching rule decides; no match allows. Call after client_allowed().
    [[nodiscard]] RuleAction decide(const IpAddress& client, core::UnitId unit, core::FunctionCode function,
                                    std::optional<RegisterRange> request) const noexcept;
    bool operator==(const ModbusTcpConfig&) const = default;
};

/// Kernel RS-485 mode (TIOCSRS485): the driver switches the transceiver.
struct Rs485Config {
    bool enabled = false;
    bool rts_on_send = true;
    bool rts_after_send = false;
    milliseconds delay_before_send{0};
    milliseconds delay_after_send{0};
    static constexpr Range<milliseconds> delay_range{milliseconds{0}, milliseconds{1000}};
    bool operator==(const Rs485Config&) const = default;
};

/// Poll periods; their meaning is the profile's: fast = status, slow = I/O and
/// parameters, motion = status while a motion runs (spec section 3 rule 5).
struct PollConfig {
    milliseconds fast{50};
    milliseconds slow = seconds{1};
    milliseconds motion{20};
    static constexpr Range<milliseconds> period_range{milliseconds{1}, std::chrono::hours{1}};
    bool operator==(const PollConfig&) const = default;
};

/// A register block of a generic Modbus device.
struct RegisterBlock {
    RegisterTable table = RegisterTable::holding;  ///< required in the file
    std::uint16_t address = 0;                     ///< required
    std::uint16_t count = 0;                       ///< required; 1..125 registers or 1..2000 bits
    milliseconds period = seconds{1};
    bool writable = false;  ///< coils and holding only: TCP writes are forwarded
    static constexpr Range<milliseconds> period_range{milliseconds{1}, std::chrono::hours{1}};
    /// Modbus Application Protocol V1.1b3 section 6.1-6.4: one read carries at most
    /// 2000 bits or 125 registers.
    static constexpr std::uint16_t max_bits = 2000;
    static constexpr std::uint16_t max_registers = 125;
    bool operator==(const RegisterBlock&) const = default;
};

struct DeviceConfig {
    std::string name;                           ///< required; unique in the whole config
    DeviceType type = DeviceType::modbus;       ///< required
    core::BusAddress address;                   ///< required; see address_range()
    core::UnitId unit_id;                       ///< required; unique across the config
    milliseconds max_age{200};                  ///< image freshness for TCP reads; 0: always ask
    static constexpr Range<milliseconds> max_age_range{milliseconds{0}, std::chrono::hours{1}};
    milliseconds command_ttl{500};              ///< a command not started by then is rejected
    static constexpr Range<milliseconds> command_ttl_range{milliseconds{1}, std::chrono::minutes{1}};
    milliseconds delay_before_command{0};
    static constexpr Range<milliseconds> delay_before_command_range{milliseconds{0}, seconds{1}};
    std::size_t queue_limit = 16;               ///< queued requests before exception 0x06
    static constexpr Range<std::int64_t> queue_limit_range{1, 1024};
    /// Per-device pacing: at least this long between the end of one of its replies
    /// (or its timeout) and the next request to it; other devices use the line meanwhile.
    milliseconds request_gap{0};
    /// After the line opens or reconnects, before the first request to this device.
    milliseconds first_request_delay{0};
    static constexpr Range<milliseconds> pacing_range{milliseconds{0}, std::chrono::minutes{1}};
    PollConfig poll;                            ///< not for `modbus`: blocks have periods
    bool allow_protected = false;               ///< device ID / flash save / baud / mode writes
    bool mqtt_commands = true;
    WordOrder word_order = WordOrder::high_first;  ///< excd203mb and modbus only
    std::optional<std::uint32_t> stroke;        ///< wtec-ascii only, required there
    static constexpr Range<std::int64_t> stroke_range{1, 0x7FFF'FFFF};
    std::vector<RegisterBlock> blocks;          ///< modbus only, required there
    /// `type:` as written: a built-in type's name, or a device definition's name
    /// (then `type` is DeviceType::modbus, or the definition's behaviour, and
    /// `definition_file` says where it came from).
    std::string type_name;
    std::string definition_file;                ///< "" for generic devices without one and built-ins compiled in
    /// Points and alarms (the definition's, then the inline ones) and `max_gap`;
    /// empty for the built-in types.
    core::PointModel points;
    /// Built-in types: the register map of the definition file that replaces the
    /// compiled-in one (docs/devices.md, "Built-in types"); empty when the compiled-in
    /// definition is used, and for generic devices.
    std::vector<core::RegisterDef> registers;
    /// Built-in types: the points and alarms of the definition file that decode the
    /// hook's state (docs/devices.md, "Built-in types"); nullopt when the compiled-in
    /// definition's apply (no file, or a file without points:). Not `points`: a
    /// built-in type's fields are not written or read by name over MQTT.
    std::optional<core::PointModel> builtin_state = std::nullopt;
    /// Generic devices: the poll period of points (and blocks) that set none.
    milliseconds period = seconds{1};
    /// Registers (bits) no point names that one merged read may bridge.
    static constexpr Range<std::int64_t> max_gap_range{0, 124};
    bool operator==(const DeviceConfig&) const = default;
};

struct LineConfig {
    std::string name;  ///< required; unique among lines
    std::string port;  ///< required; absolute device path or tcp://host:port, unique among lines
    /// Set when `port` is tcp://host:port: the line is reached through a serial device
    /// server in transparent mode (docs/service.md, "Serial device servers").
    std::optional<TcpEndpoint> tcp;
    std::uint32_t baud = 115200;
    /// Rates the serial layer sets up (libmodbus maps exactly these to termios).
    static constexpr std::array<std::uint32_t, 13> standard_bauds{
        1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200, 230400, 460800, 500000, 576000, 921600};
    Parity parity = Parity::none;
    unsigned data_bits = 8;  ///< 7 or 8
    unsigned stop_bits = 1;  ///< 1 or 2
    Rs485Config rs485;
    bool local_echo = false;  ///< 2-wire adapter echoes what it sends: discard it
    milliseconds response_timeout{100};
    static constexpr Range<milliseconds> response_timeout_range{milliseconds{1}, seconds{10}};
    /// Inter-character backstop. When absent from the file: 5ms, or 3.5 character
    /// times when that is longer (below 9600 bit/s).
    milliseconds byte_timeout{5};
    static constexpr milliseconds default_byte_timeout{5};
    static constexpr Range<milliseconds> byte_timeout_range{milliseconds{1}, seconds{1}};
    /// Guard after a reply before the next request, on top of the 3.5-character
    /// silence that is always kept (they overlap). 0: the silence alone, which is
    /// what the line's physical rate assumes (spec section 9).
    milliseconds turnaround{0};
    static constexpr Range<milliseconds> turnaround_range{milliseconds{0}, seconds{1}};
    /// After a broadcast, before the next request: every slave must have acted on it
    /// (Modbus over Serial Line V1.02, 2.4.1: "turnaround delay", typically 100-200 ms).
    milliseconds broadcast_delay{100};
    static constexpr Range<milliseconds> broadcast_delay_range{milliseconds{0}, seconds{10}};
    /// Precise silence timing: the worker wakes precise_timing_lead before a request's
    /// silence ends and spins the last stretch on the loop thread, so the request
    /// leaves at the instant instead of when a timer wake-up gets round to it (line
    /// rate for CPU: docs/configuration.md). When absent from the file: true when the
    /// whole silence is shorter than the lead (spun without a timer), else false.
    bool precise_timing = false;
    static constexpr std::chrono::microseconds precise_timing_lead{200};
    /// Silence the gateway leaves between frames: at least t3.5 of the line's baud;
    /// 0: t3.5 alone. Over TCP the device server forwards bytes as they come, so the
    /// gateway keeps the silence of the far side's line.
    milliseconds request_gap{0};
    static constexpr Range<milliseconds> request_gap_range{milliseconds{0}, seconds{1}};
    /// tcp:// ports only: a reply ends when its length is complete, or at a gap this
    /// long between two segments (replaces byte_timeout, which a stream cannot see).
    /// When absent from the file: 5ms, or 3.5 character times when that is longer.
    milliseconds tcp_frame_gap{5};
    static constexpr Range<milliseconds> tcp_frame_gap_range{milliseconds{1}, seconds{1}};
    /// tcp:// ports only: how long a connection attempt may take.
    milliseconds connect_timeout = seconds{2};
    static constexpr Range<milliseconds> connect_timeout_range{milliseconds{10}, std::chrono::minutes{1}};
    /// tcp:// ports only: the wait before connecting again after a failure, doubling
    /// up to max (serial ports reopen on offline_backoff).
    Backoff reconnect_backoff{milliseconds{250}, milliseconds{500}};
    unsigned read_retries = 1;  ///< writes are never retried (spec section 3 rule 6)
    static constexpr Range<std::int64_t> read_retries_range{0, 5};
    unsigned offline_after = 3;  ///< consecutive timeouts
    static constexpr Range<std::int64_t> offline_after_range{1, 100};
    Backoff offline_backoff{seconds{1}, seconds{30}};
    std::optional<core::UnitId> broadcast_unit;  ///< Modbus TCP unit that broadcasts on this line
    /// Percent of the line's time its broadcasts may take (frame + t3.5 +
    /// broadcast_delay each); a broadcast beyond it is refused with 0x06, so polls and
    /// the other devices keep their rates.
    unsigned broadcast_share = 10;
    static constexpr Range<std::int64_t> broadcast_share_range{1, 100};
    std::vector<DeviceConfig> devices;

    /// Start + data + parity + stop bits.
    [[nodiscard]] unsigned bits_per_character() const noexcept;
    /// One character on the wire at this baud.
    [[nodiscard]] std::chrono::nanoseconds character_time() const noexcept;
    bool operator==(const LineConfig&) const = default;
};

struct UpstreamUnitConfig {
    core::UnitId unit_id;                   ///< required; gateway unit, unique across the config
    core::UnitId upstream_unit{1};          ///< unit on the upstream (the R6 manual's examples use 1)
    std::string name;                ///< required; MQTT device name, unique with device names
    bool operator==(const UpstreamUnitConfig&) const = default;
};

/// A Modbus TCP server reached by pass-through (Huacheng R6).
struct UpstreamConfig {
    std::string name;  ///< required; unique among upstreams
    std::string host;  ///< required; host name or IP literal (IPv6 without brackets)
    std::uint16_t port = 502;
    milliseconds connect_timeout = seconds{2};
    static constexpr Range<milliseconds> connect_timeout_range{milliseconds{10}, std::chrono::minutes{1}};
    milliseconds response_timeout = seconds{1};
    static constexpr Range<milliseconds> response_timeout_range{milliseconds{1}, std::chrono::minutes{1}};
    Backoff reconnect_backoff{milliseconds{500}, seconds{30}};
    milliseconds poll_period{500};  ///< R6 state polled for MQTT
    static constexpr Range<milliseconds> poll_period_range{milliseconds{10}, std::chrono::hours{1}};
    milliseconds command_ttl = seconds{1};
    static constexpr Range<milliseconds> command_ttl_range{milliseconds{1}, std::chrono::minutes{1}};
    std::size_t queue_limit = 32;
    static constexpr Range<std::int64_t> queue_limit_range{1, 1024};
    /// A stateful sequence (counter select, data-source set-up) holds its registers
    /// against other clients at most this long after it began, whatever its owner does.
    milliseconds sequence_max_hold{500};
    static constexpr Range<milliseconds> sequence_max_hold_range{milliseconds{10}, seconds{10}};
    std::vector<UpstreamUnitConfig> units;  ///< at least one
    bool operator==(const UpstreamConfig&) const = default;
};

struct MqttTlsConfig {
    std::string ca_file;    ///< empty: the system's trust store
    std::string cert_file;  ///< client certificate (may hold the key too)
    std::string key_file;   ///< needs cert_file
    bool verify = true;     ///< verify the broker's certificate and host name
    bool operator==(const MqttTlsConfig&) const = default;
};

struct MqttConfig {
    /// False when the `mqtt` section is absent; true by default when it is present.
    bool enabled = false;
    /// tcp:// | ssl:// | ws:// | wss://; mqtt.uri, one or a list: tried in order
    /// (the next after a failed attempt or a lost connection); all TLS or none.
    std::vector<std::string> uris{"tcp://127.0.0.1:1883"};
    std::string client_id;  ///< resolved: "fieldbridge-<gateway id>" when not set
    std::string username;   ///< empty: none
    std::string password;   ///< resolved: the content of password_file when that is set
    std::string password_file;  ///< absolute path, or empty
    MqttTlsConfig tls;      ///< file paths resolved to absolute paths
    int qos = 1;
    static constexpr Range<std::int64_t> qos_range{0, 2};
    milliseconds keep_alive = seconds{30};  ///< whole seconds; 0 disables
    static constexpr Range<milliseconds> keep_alive_range{milliseconds{0}, seconds{65535}};
    bool clean_session = true;
    MqttVersion version = MqttVersion::v3_1_1;
    std::string prefix;     ///< resolved: "fieldbridge/<gateway id>" when not set
    milliseconds heartbeat = seconds{60};
    static constexpr Range<milliseconds> heartbeat_range{seconds{1}, std::chrono::hours{24}};
    milliseconds min_interval{200};
    static constexpr Range<milliseconds> min_interval_range{milliseconds{0}, std::chrono::hours{1}};
    std::map<std::string, double> deadband;  ///< state field -> smallest change published
    milliseconds diag_period = seconds{10};
    static constexpr Range<milliseconds> diag_period_range{seconds{1}, std::chrono::hours{1}};
    Backoff reconnect_backoff{seconds{1}, seconds{60}};
    /// A larger command payload gets an error result (`too_large`) and is not parsed.
    std::size_t max_command_bytes = 16 * 1024;
    static constexpr Range<std::int64_t> max_command_bytes_range{256, 1024 * 1024};
    /// A command `id` is echoed in its result, and logged, up to this many bytes.
    std::size_t max_command_id_length = 128;
    static constexpr Range<std::int64_t> max_command_id_length_range{8, 4096};
    /// Commands received and not yet handled; beyond either bound they are dropped.
    std::size_t max_queued_commands = 64;
    static constexpr Range<std::int64_t> max_queued_commands_range{1, 4096};
    std::size_t max_queued_command_bytes = 1024 * 1024;
    static constexpr Range<std::int64_t> max_queued_command_bytes_range{1024, 64 * 1024 * 1024};
    /// Publications waiting for the broker, in payload + topic bytes.
    std::size_t outbox_max_bytes = 4 * 1024 * 1024;
    static constexpr Range<std::int64_t> outbox_max_bytes_range{64 * 1024, 256 * 1024 * 1024};
    /// The same bound in messages: what a broker outage may keep of alarm events and
    /// command results (retained state takes one place per topic).
    std::size_t outbox_max_messages = 512;
    static constexpr Range<std::int64_t> outbox_max_messages_range{16, 1000000};
    static constexpr std::size_t max_client_id_length = 128;
    static constexpr std::size_t max_prefix_length = 256;

    /// ssl:// or wss:// (the first URI; all of them are the same on this).
    [[nodiscard]] bool uses_tls() const noexcept;
    bool operator==(const MqttConfig&) const = default;
};

/// The Sparkplug B edge node's offline buffer (docs/sparkplug-session.md): data kept
/// while no session can carry it. The defaults fit a 512 MB box: 16 MiB is about 3 %
/// of its memory, and holds some 4 minutes of 64 devices changing every second (half
/// an hour for a box of 8).
struct SparkplugOfflineBufferConfig {
    std::size_t max_messages = 20000;
    static constexpr Range<std::int64_t> max_messages_range{1, 1000000};
    std::size_t max_bytes = 16 * 1024 * 1024;
    static constexpr Range<std::int64_t> max_bytes_range{64 * 1024, 256 * 1024 * 1024};
    bool operator==(const SparkplugOfflineBufferConfig&) const = default;
};

/// The Sparkplug B edge node (docs/sparkplug-session.md, docs/configuration.md): its own
/// MQTT connection beside the JSON bridge. Present only when the section is.
struct SparkplugConfig {
    std::vector<std::string> servers;  ///< tcp:// | ssl://, tried in order; at least one
    std::string client_id;             ///< resolved: "fieldbridge-<gateway id>-sparkplug" when not set
    std::string group_id;
    std::string edge_node_id;          ///< resolved: the gateway id when not set
    std::string primary_host_id;       ///< empty: no primary host
    std::string username;              ///< empty: none
    std::string password;              ///< resolved: the content of password_file when that is set
    std::string password_file;         ///< absolute path, or empty
    MqttTlsConfig tls;                 ///< file paths resolved to absolute paths
    milliseconds keep_alive = seconds{30};  ///< whole seconds; 0 disables
    static constexpr Range<milliseconds> keep_alive_range{milliseconds{0}, seconds{65535}};
    bool aliases = true;
    SparkplugOfflineBufferConfig offline_buffer;
    /// Where the bdSeq file lives. Resolved: $STATE_DIRECTORY (systemd's
    /// StateDirectory=; its first path) when not set, else /var/lib/fieldbridge.
    std::string state_dir;
    static constexpr const char* default_state_dir = "/var/lib/fieldbridge";

    /// True when a server is ssl://.
    [[nodiscard]] bool uses_tls() const noexcept;
    bool operator==(const SparkplugConfig&) const = default;
};

/// Prometheus text endpoint.
struct MetricsHttpConfig {
    ListenAddress listen{"127.0.0.1", 9102};
    bool operator==(const MetricsHttpConfig&) const = default;
};

struct Config {
    GatewayConfig gateway;
    ModbusTcpConfig modbus_tcp;
    std::vector<LineConfig> lines;
    std::vector<UpstreamConfig> upstreams;
    MqttConfig mqtt;
    std::optional<SparkplugConfig> sparkplug;       ///< absent: no Sparkplug edge node
    std::optional<MetricsHttpConfig> metrics_http;  ///< absent: no HTTP endpoint
    std::string source_file;                        ///< the file it was loaded from
    bool operator==(const Config&) const = default;
};

}  // namespace fieldbridge::config
