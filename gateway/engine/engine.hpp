#pragma once
/// @file engine.hpp
/// The line engine of one configuration: a LineWorker per line (the only owner of its
/// port) and a DeviceAgent per device, wired together: agents submit to their line's
/// worker, the line's health and port state reach the agents. Northbound servers find
/// devices here by Modbus unit ID or by name.
///
/// Loop thread only. The engine is rebuilt, not patched, when the lines or devices of
/// the configuration change (daemon/engine_component.hpp).
#include <asio/io_context.hpp>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "config/config.hpp"
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
    std::uint8_t unit_id = 0;
    bool mqtt_commands = true;
};

/// One line and its devices.
struct LineEntry {
    std::unique_ptr<LineWorker> worker;
    std::vector<std::unique_ptr<DeviceAgent>> agents;  ///< by DeviceIndex
    std::optional<std::uint8_t> broadcast_unit;
    /// The line's shortest command_ttl: a broadcast acts no later than any of its
    /// devices would accept a command.
    Duration broadcast_ttl = std::chrono::milliseconds{500};
    /// Percent of the line's time its broadcasts may take (config broadcast_share).
    unsigned broadcast_share = 10;
};

class Engine {
public:
    /// Builds every line and device (nothing is opened until start()). Throws
    /// ProfileError or std::invalid_argument naming the line/device for options the
    /// engine cannot use (config validation rejects those first).
    Engine(asio::io_context& io, const config::Config& config, LogSink log, PortFactory ports = posix_port_factory());
    ~Engine();
    Engine(const Engine&) = delete;
    Engine& operator=(const Engine&) = delete;

    /// Opens every port (failures are retried by the workers) and starts polling.
    void start();
    /// Stops polling, completes everything queued `cancelled`, closes the ports.
    void stop();

    /// By Modbus TCP unit ID; nullptr when no serial device has it.
    [[nodiscard]] DeviceAgent* find_unit(std::uint8_t unit_id) const noexcept;
    /// By configured device name; nullptr when unknown.
    [[nodiscard]] DeviceAgent* find_device(std::string_view name) const noexcept;
    [[nodiscard]] const std::vector<DeviceEntry>& devices() const noexcept { return devices_; }
    [[nodiscard]] const std::vector<LineEntry>& lines() const noexcept { return lines_; }

    /// For systemd STATUS=: "lines 2/2 up, devices 4/4 online".
    [[nodiscard]] std::string status() const;

private:
    std::vector<LineEntry> lines_;
    std::vector<DeviceEntry> devices_;
    LogSink log_;
    bool started_ = false;
};

}  // namespace fieldbridge::engine
