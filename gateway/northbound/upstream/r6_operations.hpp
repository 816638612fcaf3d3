#pragma once
/// @file r6_operations.hpp
/// The MQTT operations of a Huacheng R6 unit (docs/mqtt.md, "Huacheng R6"; seed 004
/// 3.2.1, 3.2.2, 3.3.3) over the registers of r6_map.hpp: stop, pause, start,
/// clear_alarm, global_speed, output. The R6 has no device profile (the controller
/// checks values beyond these ranges): this table is its MQTT profile.
#include "engine/profiles/operations.hpp"

namespace fieldbridge::northbound::r6 {

[[nodiscard]] engine::OperationSet r6_operations();

}  // namespace fieldbridge::northbound::r6
