#pragma once
/// @file r6_source.hpp
/// The units of a Huacheng R6 pass-through (northbound/upstream) as DeviceSources of
/// the MQTT bridge: state and alarms from the target's R6 state poller, change
/// notifications from its state callback, commands sent through the target like a
/// Modbus TCP client's (same queue discipline: writes to the command block are
/// commands). The R6 has no device profile: its operations (r6_operations.hpp) hold
/// the only local checks, and the controller answers the rest.
///
/// The target's state callback is taken over (one per target). The target must
/// outlive the sources or be detached from them first (detach_r6_sources()). Loop
/// thread only.
#include <cstddef>
#include <memory>
#include <vector>

#include "northbound/mqtt/device_source.hpp"
#include "northbound/upstream/upstream_target.hpp"

namespace fieldbridge::northbound::mqtt {

/// One source per unit of @p target's configuration, @p copies times (unit order within
/// each copy): one copy per consumer (each source has its own listener), all fed by the
/// target's one state callback, which this takes over.
[[nodiscard]] std::vector<std::shared_ptr<DeviceSource>> make_r6_sources(asio::io_context& io,
                                                                         upstream::UpstreamTarget& target,
                                                                         std::size_t copies = 1);
/// The target is going away: the sources report offline and answer commands 0x0A.
void detach_r6_sources(const std::vector<std::shared_ptr<DeviceSource>>& sources);

}  // namespace fieldbridge::northbound::mqtt
