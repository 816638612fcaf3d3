#pragma once
/// @file engine.hpp
/// The line engine of one configuration: a LineWorker per line (the only owner of its
/// port) and a DeviceAgent per device, wired together: agents submit to their line's
/// worker, the line's health and port state reach the agents. Northbound servers find
/// devices here by Modbus unit ID or by name.
///
/// Loop thread only. A reload applies the difference (apply()): a line whose settings
/// and devices did not change keeps its worker, port, queue and transaction in flight;
/// a device whose profile settings changed is swapped on a line that keeps running; a
/// line whose serial or timing settings changed restarts (docs/architecture.md, "Reload").
#include <asio/io_context.hpp>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "config/config.hpp"
#include "core/modbus_ids.hpp"
#include "engine/device_agent.hpp"
#include "engine/line_log.hpp"
#include "engine/line_worker.hpp"
#include "engine/serial_port.hpp"

namespace fieldbridge::engine {

/// Makes the port of a line (tests and benchmarks may wrap the POSIX one).
using PortFactory = std::function<std::unique_ptr<SerialPort>(const SerialSettings&)>;
/// The POSIX serial port (libmodbus set-up).
[[nodiscard]] PortFactory posix_port_factory();

/// A device as the northbound servers see it.
struct DeviceEntry {
    std::string_view line;
    DeviceAgent* agent = nullptr;
    core::UnitId unit_id;
    bool mqtt_commands = true;
};

/// One line and its devices.
struct LineEntry {
    std::unique_ptr<LineWorker> worker;
    /// In configuration order; each agent's config().index is its scheduler index
    /// (indices are not reused within a line: a swapped device gets a new one).
    std::vector<std::unique_ptr<DeviceAgent>> agents;
    std::optional<core::UnitId> broadcast_unit;
    /// The line's shortest command_ttl: a broadcast acts no later than any of its
    /// devices would accept a command.
    Duration broadcast_ttl = std::chrono::milliseconds{500};
    /// Percent of the line's time its broadcasts may take (config broadcast_share).
    unsigned broadcast_share = 10;
    /// Changes whenever a reload replaced the worker or any agent of this line:
    /// whoever keeps objects built on them (Modbus TCP targets) rebuilds those then.
    std::uint64_t revision = 0;
    /// What the line was built from (compared on reload).
    config::LineConfig config;
    /// Agents replaced by a reload: stopped, kept until the next reload so that their
    /// requests still queued on the line complete normally (never cancelled).
    std::vector<std::unique_ptr<DeviceAgent>> retired;
    DeviceIndex next_index = 0;
};

/// What a reload did, line by line and device by device (for the log and tests).
struct ReloadReport {
    std::vector<std::string> lines_kept;       ///< untouched: port, queue, in-flight transaction
    std::vector<std::string> lines_updated;    ///< devices or line policies changed; port stays open
    std::vector<std::string> lines_restarted;  ///< serial or timing settings changed: port reopened
    std::vector<std::string> lines_added;
    std::vector<std::string> lines_removed;
    std::vector<std::string> devices_retuned;   ///< freshness/command timing/limits in place
    std::vector<std::string> devices_replaced;  ///< new profile settings: a new agent, same port
    std::vector<std::string> devices_added;
    std::vector<std::string> devices_removed;

    [[nodiscard]] bool changed() const noexcept;
    /// "lines kept: a; restarted: b; devices retuned: x" (empty parts left out).
    [[nodiscard]] std::string summary() const;
};

class Engine {
public:
    /// Builds every line and device (nothing is opened until start()). Throws
    /// ProfileError or core::InvalidArgument naming the line/device for options the
    /// engine cannot use (config validation rejects those first).
    Engine(asio::io_context& io, const config::Config& config, LogSink log, PortFactory ports = posix_port_factory());
    ~Engine();
    Engine(const Engine&) = delete;
    Engine& operator=(const Engine&) = delete;

    /// Opens every port (failures are retried by the workers) and starts polling.
    void start();
    /// Stops polling, completes everything queued `cancelled`, closes the ports.
    void stop();

    /// Reload (after start()): brings the engine to @p config, touching only what
    /// changed (see the file comment). Throws like the constructor for a line or
    /// device it cannot build; lines already handled stay as applied.
    ReloadReport apply(const config::Config& config);

    /// By Modbus TCP unit ID; nullptr when no serial device has it.
    [[nodiscard]] DeviceAgent* find_unit(core::UnitId unit_id) const noexcept;
    /// By configured device name; nullptr when unknown.
    [[nodiscard]] DeviceAgent* find_device(std::string_view name) const noexcept;
    [[nodiscard]] const std::vector<DeviceEntry>& devices() const noexcept { return devices_; }
    [[nodiscard]] const std::vector<LineEntry>& lines() const noexcept { return lines_; }

    /// For systemd STATUS=: "lines 2/2 up, devices 4/4 online".
    [[nodiscard]] std::string status() const;

private:
    [[nodiscard]] LineEntry build_line(const config::LineConfig& line);
    [[nodiscard]] std::unique_ptr<DeviceAgent> build_agent(LineEntry& entry, const config::LineConfig& line,
                                                           const config::DeviceConfig& device);
    /// Health and port state of the worker reach the line's current agents.
    static void wire_health(LineEntry& entry);
    static void set_broadcast(LineEntry& entry, const config::LineConfig& line);
    /// A line with the same serial and timing settings: devices and policies in place.
    void update_line(LineEntry& entry, const config::LineConfig& line, ReloadReport& report);
    void index_devices();

    asio::io_context& io_;
    PortFactory ports_;
    std::vector<LineEntry> lines_;
    /// Lines a reload stopped (removed or restarted): their ports are closed; they are
    /// destroyed at the next reload, once nothing refers to their agents any more.
    std::vector<LineEntry> retired_lines_;
    std::vector<DeviceEntry> devices_;
    LogSink log_;
    bool started_ = false;
};

}  // namespace fieldbridge::engine
