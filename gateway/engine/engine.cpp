#include "engine/engine.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "engine/engine_settings.hpp"
#include "engine/posix_serial_port.hpp"
#include "engine/profiles/profile_factory.hpp"

namespace fieldbridge::engine {

PortFactory posix_port_factory() {
    return [](const SerialSettings& settings) -> std::unique_ptr<SerialPort> {
        return std::make_unique<PosixSerialPort>(settings);
    };
}

Engine::Engine(asio::io_context& io, const config::Config& config, LogSink log, PortFactory ports)
    : log_(std::move(log)) {
    lines_.reserve(config.lines.size());
    for (const auto& line : config.lines) {
        LineEntry entry;
        entry.broadcast_unit = line.broadcast_unit;
        entry.broadcast_share = line.broadcast_share;
        for (std::size_t i = 0; i < line.devices.size(); ++i) {
            const auto& device = line.devices[i];
            if (i == 0 || device.command_ttl < entry.broadcast_ttl) entry.broadcast_ttl = device.command_ttl;
        }
        entry.worker = std::make_unique<LineWorker>(io, line_worker_config(line), ports(serial_settings(line)), log_);
        for (std::size_t i = 0; i < line.devices.size(); ++i) {
            const auto& device = line.devices[i];
            const auto index = static_cast<DeviceIndex>(i);
            std::unique_ptr<DeviceProfile> profile;
            try {
                profile = make_profile(to_engine(device.type), profile_options(device));
            } catch (const ProfileError& error) {
                throw ProfileError(fmt::format("line {}, device {}: {}", line.name, device.name, error.what()));
            }
            entry.worker->scheduler().add_device(index, device_limits(line, device), device.name);
            LineWorker* worker = entry.worker.get();
            entry.agents.push_back(std::make_unique<DeviceAgent>(
                io, device_agent_config(line, device, index), std::move(profile),
                [worker](Transaction transaction) { worker->submit(std::move(transaction)); }, log_));
        }
        // Health reaches the agent of the device; the port going down takes every
        // device of the line offline, and its coming back makes them stale until read.
        std::vector<DeviceAgent*> agents;
        for (const auto& agent : entry.agents) agents.push_back(agent.get());
        entry.worker->scheduler().set_health_callback([agents](DeviceIndex device, bool online, TimePoint now) {
            if (device < agents.size()) agents[device]->on_health(online, now);
        });
        entry.worker->set_state_callback([agents](bool up, TimePoint now) {
            for (auto* agent : agents) agent->on_health(up, now);
        });
        lines_.push_back(std::move(entry));
    }
    for (std::size_t l = 0; l < config.lines.size(); ++l) {
        const auto& line = config.lines[l];
        for (std::size_t d = 0; d < line.devices.size(); ++d) {
            devices_.push_back(DeviceEntry{lines_[l].worker->config().name, lines_[l].agents[d].get(),
                                           line.devices[d].unit_id, line.devices[d].mqtt_commands});
        }
    }
}

Engine::~Engine() { stop(); }

void Engine::start() {
    if (started_) return;
    started_ = true;
    for (auto& line : lines_) line.worker->start();
    for (auto& line : lines_) {
        for (auto& agent : line.agents) agent->start();
    }
}

void Engine::stop() {
    if (!started_) return;
    started_ = false;
    for (auto& line : lines_) {
        for (auto& agent : line.agents) agent->stop();
    }
    for (auto& line : lines_) line.worker->stop();
}

DeviceAgent* Engine::find_unit(std::uint8_t unit_id) const noexcept {
    for (const auto& device : devices_) {
        if (device.unit_id == unit_id) return device.agent;
    }
    return nullptr;
}

DeviceAgent* Engine::find_device(std::string_view name) const noexcept {
    for (const auto& device : devices_) {
        if (device.agent->config().name == name) return device.agent;
    }
    return nullptr;
}

std::string Engine::status() const {
    std::size_t up = 0;
    for (const auto& line : lines_) up += line.worker->line_up() ? 1 : 0;
    std::size_t online = 0;
    for (const auto& device : devices_) online += device.agent->online() ? 1 : 0;
    return fmt::format("lines {}/{} up, devices {}/{} online", up, lines_.size(), online, devices_.size());
}

}  // namespace fieldbridge::engine
