#pragma once
/// @file engine_settings.hpp
/// The configuration of the line engine, taken from the validated config::Config:
/// pure functions, one per engine part, so that each mapping is tested on its own and
/// the engine assembly only wires parts together. Names and defaults are the
/// config's (docs/configuration.md).
#include "config/config.hpp"
#include "engine/device_agent.hpp"
#include "engine/line_scheduler.hpp"
#include "engine/line_timing.hpp"
#include "engine/line_worker.hpp"
#include "engine/profiles/device_profile.hpp"
#include "engine/serial_port.hpp"

namespace fieldbridge::engine {

/// Port set-up: path, character format and the kernel RS-485 options.
[[nodiscard]] SerialSettings serial_settings(const config::LineConfig& line);
/// Silence, timeouts, turnaround guard, echo, ASCII timeouts (the manual's 5 / 50 ms).
[[nodiscard]] LineTimingConfig line_timing(const config::LineConfig& line);
/// Timing, scheduler and reopen back-off of the line's worker.
[[nodiscard]] LineWorkerConfig line_worker_config(const config::LineConfig& line);
/// Queue and health policy of one device of @p line.
[[nodiscard]] DeviceLimits device_limits(const config::LineConfig& line, const config::DeviceConfig& device);
/// What the device's profile takes from its configuration.
[[nodiscard]] ProfileOptions profile_options(const config::DeviceConfig& device);
/// Name, address, freshness and command timing of the device's agent.
[[nodiscard]] DeviceAgentConfig device_agent_config(const config::LineConfig& line,
                                                    const config::DeviceConfig& device, DeviceIndex index);

}  // namespace fieldbridge::engine
