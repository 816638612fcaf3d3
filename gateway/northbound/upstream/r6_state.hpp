#pragma once
/// @file r6_state.hpp
/// The R6 state the gateway polls for MQTT (spec §5; seed 004 3.1.5-3.1.15), pure:
/// which reads one poll cycle makes, and how the register image decodes into named
/// fields and alarms. The image holds the registers as read (holding table); the
/// decoding joins the 32-bit (high word first) and 64-bit (highest word first) values.
///
/// Fields (only those whose registers are known):
///   mode (1 manual, 2 auto, 3 configuration), mode_name, alarm, alarm_active,
///   moving, origin_set, axis_count, axes_deg (array of axis_count numbers, J1
///   first, deg), world_mm (array X Y Z U V W M7 M8, mm as the manual states; spec
///   §6 shows both as arrays), cycle_time and last_cycle_time (ms).
#include <cstddef>
#include <optional>
#include <vector>

#include "engine/profiles/device_profile.hpp"
#include "engine/register_image.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::northbound::upstream {

/// Reads of one poll cycle, in order: mode; axis count; axis positions (as many as
/// the axis count just read says; skipped when 0 or unknown); world coordinates;
/// alarm number with both cycle times (0x095C-0x0964, one read); move and origin state.
inline constexpr std::size_t r6_poll_steps = 6;

/// The FC03 read of poll step @p step, or nullopt when the step has nothing to read.
[[nodiscard]] std::optional<protocol::ReadRegistersRequest> r6_poll_read(std::size_t step,
                                                                        const engine::RegisterImage& image);

[[nodiscard]] engine::DecodedState decode_r6_state(const engine::RegisterImage& image);
/// A non-zero alarm number is one alarm, code "r6_alarm_<n>".
[[nodiscard]] std::vector<engine::Alarm> r6_alarms(const engine::RegisterImage& image);

}  // namespace fieldbridge::northbound::upstream
