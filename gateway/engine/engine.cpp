#include "engine/engine.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <stdexcept>

#include "core/error.hpp"
#include "engine/engine_settings.hpp"
#include "engine/posix_serial_port.hpp"
#include "engine/tcp_stream_port.hpp"
#include "engine/profiles/profile_factory.hpp"

namespace fieldbridge::engine {

PortFactory posix_port_factory() {
    return [](const SerialSettings& settings) -> std::unique_ptr<SerialPort> {
        if (settings.tcp) return std::make_unique<TcpStreamPort>(settings, ConnectWait::begin);
        return std::make_unique<PosixSerialPort>(settings);
    };
}

namespace {

/// The settings a line's worker and port are built from: when any differs the line
/// restarts (its port is closed and opened again). Everything else of a line (its
/// devices, retries, offline threshold, broadcast unit and share) changes in place.
[[nodiscard]] bool same_port_and_timing(const config::LineConfig& a, const config::LineConfig& b) {
    config::LineConfig left = a;
    config::LineConfig right = b;
    for (auto* line : {&left, &right}) {
        line->devices.clear();
        line->read_retries = 0;
        line->offline_after = 0;
        line->broadcast_unit.reset();
        line->broadcast_share = 0;
    }
    return left == right;
}

/// @p device without what retune() and the scheduler's update_device() take, and what
/// only routing reads.
[[nodiscard]] config::DeviceConfig without_agent_settings(config::DeviceConfig device) {
    device.max_age = {};
    device.command_ttl = {};
    device.delay_before_command = {};
    device.queue_limit = 0;
    device.unit_id = {};
    device.mqtt_commands = false;
    return device;
}

/// A device whose profile and agent settings are unchanged but for what retune()
/// and the scheduler's update_device() take, and what only routing reads.
[[nodiscard]] bool retunable(const config::DeviceConfig& a, const config::DeviceConfig& b) {
    return without_agent_settings(a) == without_agent_settings(b);
}

/// @p device without what does not change what its registers mean: the agent's
/// settings, poll periods and protection.
[[nodiscard]] config::DeviceConfig register_meaning(const config::DeviceConfig& device) {
    config::DeviceConfig meaning = without_agent_settings(device);
    meaning.poll = {};
    meaning.allow_protected = false;
    for (auto& block : meaning.blocks) block.period = {};
    return meaning;
}

/// A swapped device whose registers mean what they meant (same device type, bus
/// address, word order, stroke and blocks): the new agent may start from the old one's
/// register image.
[[nodiscard]] bool same_registers(const config::DeviceConfig& a, const config::DeviceConfig& b) {
    return register_meaning(a) == register_meaning(b);
}

[[nodiscard]] const config::DeviceConfig* find_device_config(const config::LineConfig& line,
                                                             std::string_view name) noexcept {
    for (const auto& device : line.devices) {
        if (device.name == name) return &device;
    }
    return nullptr;
}

[[nodiscard]] std::string join(const std::vector<std::string>& names) {
    std::string text;
    for (const auto& name : names) text += (text.empty() ? "" : ", ") + name;
    return text;
}

}  // namespace

bool ReloadReport::changed() const noexcept {
    return !(lines_updated.empty() && lines_restarted.empty() && lines_added.empty() && lines_removed.empty());
}

std::string ReloadReport::summary() const {
    std::string text;
    const auto part = [&text](const char* what, const std::vector<std::string>& names) {
        if (names.empty()) return;
        text += (text.empty() ? "" : "; ") + std::string(what) + ": " + join(names);
    };
    part("lines kept", lines_kept);
    part("lines updated in place", lines_updated);
    part("lines restarted", lines_restarted);
    part("lines added", lines_added);
    part("lines removed", lines_removed);
    part("devices retuned", devices_retuned);
    part("devices replaced", devices_replaced);
    part("devices added", devices_added);
    part("devices removed", devices_removed);
    return text.empty() ? "no lines" : text;
}

Engine::Engine(asio::io_context& io, const config::Config& config, LogSink log, PortFactory ports)
    : io_(io), ports_(std::move(ports)), log_(std::move(log)) {
    lines_.reserve(config.lines.size());
    for (const auto& line : config.lines) lines_.push_back(build_line(line));
    index_devices();
}

void Engine::set_broadcast(LineEntry& entry, const config::LineConfig& line) {
    entry.broadcast_unit = line.broadcast_unit;
    entry.broadcast_share = line.broadcast_share;
    for (std::size_t i = 0; i < line.devices.size(); ++i) {
        const auto& device = line.devices[i];
        if (i == 0 || device.command_ttl < entry.broadcast_ttl) entry.broadcast_ttl = device.command_ttl;
    }
}

std::unique_ptr<DeviceAgent> Engine::build_agent(LineEntry& entry, const config::LineConfig& line,
                                                 const config::DeviceConfig& device) {
    if (entry.next_index == broadcast_device) {
        throw core::InvalidArgument(fmt::format("line {}: no device index left after {} reloads that swapped "
                                                "devices; restart the service",
                                                line.name, entry.next_index));
    }
    const DeviceIndex index = entry.next_index;
    std::unique_ptr<DeviceProfile> profile;
    try {
        profile = make_profile(device.type, profile_options(device));
    } catch (const ProfileError& error) {
        throw ProfileError(fmt::format("line {}, device {}: {}", line.name, device.name, error.what()));
    }
    entry.worker->scheduler().add_device(index, device_limits(line, device), device.name);
    ++entry.next_index;
    LineWorker* worker = entry.worker.get();
    return std::make_unique<DeviceAgent>(io_, device_agent_config(line, device, index), std::move(profile),
                                         [worker](Transaction transaction) { worker->submit(std::move(transaction)); },
                                         log_);
}

void Engine::wire_health(LineEntry& entry) {
    // Health reaches the agent of the device; the port going down takes every device
    // of the line offline, and its coming back makes them stale until read.
    std::map<DeviceIndex, DeviceAgent*> by_index;
    for (const auto& agent : entry.agents) by_index[agent->config().index] = agent.get();
    entry.worker->set_health_callback([by_index](DeviceIndex device, bool online, TimePoint now) {
        if (const auto it = by_index.find(device); it != by_index.end()) it->second->on_health(online, now);
    });
    entry.worker->set_state_callback([by_index](bool up, TimePoint now) {
        for (const auto& [index, agent] : by_index) agent->on_health(up, now);
    });
}

LineEntry Engine::build_line(const config::LineConfig& line) {
    LineEntry entry;
    entry.config = line;
    set_broadcast(entry, line);
    entry.worker = std::make_unique<LineWorker>(io_, line_worker_config(line), ports_(serial_settings(line)), log_);
    for (const auto& device : line.devices) entry.agents.push_back(build_agent(entry, line, device));
    wire_health(entry);
    return entry;
}

void Engine::index_devices() {
    devices_.clear();
    for (const auto& line : lines_) {
        for (const auto& agent : line.agents) {
            const auto* device = find_device_config(line.config, agent->config().name);
            devices_.push_back(DeviceEntry{line.worker->config().name, agent.get(),
                                           device != nullptr ? device->unit_id : core::UnitId{},
                                           device == nullptr || device->mqtt_commands});
        }
    }
}

void Engine::update_line(LineEntry& entry, const config::LineConfig& line, ReloadReport& report) {
    const TimePoint now = Clock::now();
    auto& scheduler = entry.worker->scheduler();
    // Agents retired by earlier reloads leave once drained: what they had queued still
    // goes out and is answered (docs/service.md, "Reload"), even in a storm of reloads.
    std::erase_if(entry.retired, [&](const std::unique_ptr<DeviceAgent>& agent) {
        const DeviceIndex index = agent->config().index;
        if (scheduler.queued(index) != 0 || agent->requests_in_progress() != 0) return false;
        entry.worker->remove_device(index, OutcomeStatus::cancelled);
        return true;
    });

    std::vector<std::unique_ptr<DeviceAgent>> old_agents = std::move(entry.agents);
    entry.agents.clear();
    const auto take_old = [&old_agents](std::string_view name) -> std::unique_ptr<DeviceAgent> {
        for (auto& agent : old_agents) {
            if (agent && agent->config().name == name) return std::move(agent);
        }
        return nullptr;
    };
    for (const auto& device : line.devices) {
        std::unique_ptr<DeviceAgent> agent = take_old(device.name);
        const auto* before = agent ? find_device_config(entry.config, device.name) : nullptr;
        if (agent && before != nullptr && *before == device) {
            if (!(line.read_retries == entry.config.read_retries && line.offline_after == entry.config.offline_after)) {
                scheduler.update_device(agent->config().index, device_limits(line, device));
            }
            entry.agents.push_back(std::move(agent));
        } else if (agent && before != nullptr && retunable(*before, device)) {
            scheduler.update_device(agent->config().index, device_limits(line, device));
            agent->retune(device_agent_config(line, device, agent->config().index));
            report.devices_retuned.push_back(device.name);
            entry.agents.push_back(std::move(agent));
        } else {
            auto replacement = build_agent(entry, line, device);
            if (agent && before != nullptr && same_registers(*before, device)) {
                // The same registers of the same device: the cache stays warm, so the
                // clients it serves do not all go to the line at once.
                replacement->image().adopt(agent->image());
            }
            if (agent) {
                agent->stop();
                entry.worker->drop_polls(agent->config().index);
                entry.retired.push_back(std::move(agent));
                report.devices_replaced.push_back(device.name);
            } else {
                report.devices_added.push_back(device.name);
            }
            if (started_) replacement->start();
            entry.agents.push_back(std::move(replacement));
        }
    }
    for (auto& agent : old_agents) {
        if (!agent) continue;
        report.devices_removed.push_back(agent->config().name);
        agent->stop();
        entry.worker->drop_polls(agent->config().index);
        entry.retired.push_back(std::move(agent));
    }
    set_broadcast(entry, line);
    entry.config = line;
    ++entry.revision;
    wire_health(entry);
    // A new agent learns the line's state now: it was built up (online) by default.
    if (!entry.worker->line_up()) {
        for (const auto& agent : entry.agents) agent->on_health(false, now);
    }
}

ReloadReport Engine::apply(const config::Config& config) {
    ReloadReport report;
    // Lines stopped by the previous reload: nothing can reach them any more (the
    // routes and MQTT sources were re-taken after it).
    retired_lines_.clear();
    std::vector<LineEntry> old_lines = std::move(lines_);
    lines_.clear();
    lines_.reserve(config.lines.size());
    const auto take_old = [&old_lines](std::string_view name) -> std::optional<LineEntry> {
        for (auto& line : old_lines) {
            if (line.worker && line.config.name == name) return std::move(line);
        }
        return std::nullopt;
    };
    // Lines that go or restart release their ports first: a restarted line may open
    // the same port again, and a new line may take a port another line gave up.
    std::vector<std::optional<LineEntry>> kept;
    for (const auto& line : config.lines) {
        auto entry = take_old(line.name);
        if (entry && !same_port_and_timing(entry->config, line)) {
            for (auto& agent : entry->agents) agent->stop();
            entry->worker->stop();
            retired_lines_.push_back(std::move(*entry));
            entry.reset();
            report.lines_restarted.push_back(line.name);
        }
        kept.push_back(std::move(entry));
    }
    for (auto& line : old_lines) {
        if (!line.worker) continue;
        report.lines_removed.push_back(line.config.name);
        for (auto& agent : line.agents) agent->stop();
        line.worker->stop();
        retired_lines_.push_back(std::move(line));
    }
    old_lines.clear();

    for (std::size_t l = 0; l < config.lines.size(); ++l) {
        const auto& line = config.lines[l];
        if (kept[l]) {
            LineEntry entry = std::move(*kept[l]);
            if (entry.config == line) {
                report.lines_kept.push_back(line.name);
            } else {
                update_line(entry, line, report);
                report.lines_updated.push_back(line.name);
            }
            lines_.push_back(std::move(entry));
            continue;
        }
        const bool restarted = std::find(report.lines_restarted.begin(), report.lines_restarted.end(), line.name) !=
                               report.lines_restarted.end();
        if (!restarted) report.lines_added.push_back(line.name);
        lines_.push_back(build_line(line));
        if (started_) {
            lines_.back().worker->start();
            for (auto& agent : lines_.back().agents) agent->start();
        }
    }
    index_devices();
    return report;
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

DeviceAgent* Engine::find_unit(core::UnitId unit_id) const noexcept {
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
