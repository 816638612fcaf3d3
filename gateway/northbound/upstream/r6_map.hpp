#pragma once
/// @file r6_map.hpp
/// The registers of the Huacheng R6 Modbus TCP slave that the pass-through needs to
/// know about (seed 004, section 4 "address table"): the stateful indirections that
/// must not interleave between clients, the commands, and the state the gateway
/// polls for MQTT. Everything else is forwarded without interpretation.
#include <cstdint>

namespace fieldbridge::northbound::r6 {

/// An inclusive register range.
struct Span {
    std::uint16_t first = 0;
    std::uint16_t last = 0;
    [[nodiscard]] constexpr bool overlaps(std::uint32_t address, std::uint32_t count) const noexcept {
        return count > 0 && address <= last && address + count - 1 >= first;
    }
};

// seed 004 3.1.4: write the counter ID to 0x0883-0x0884, then read ID / target /
// current from 0x0883-0x0888. The selection is global in the controller.
inline constexpr Span counter_select{0x0883, 0x0884};
inline constexpr Span counter_block{0x0883, 0x0888};

// seed 004 section 4: 0x7530 selects the data source to view, 0x7531 reads its
// buffer length; the same write-then-read indirection as the counters.
inline constexpr Span source_view_select{0x7530, 0x7530};
inline constexpr Span source_view_block{0x7530, 0x7531};

// seed 004 3.3.5: 0x7532-0x7534 set up the data source to modify (ID, values per
// point, axis mask); the uploads that follow write 0x7535 (point count), 0x7536
// (clear flag) and the points up to 0x9C40, possibly over several frames.
inline constexpr Span source_edit_setup{0x7532, 0x7534};
inline constexpr Span source_edit_block{0x7532, 0x9C40};

// seed 004 3.2.1 / section 4: FC06 commands, any value executes.
inline constexpr std::uint16_t command_stop = 0x4E20;
inline constexpr std::uint16_t command_pause = 0x4E21;
inline constexpr std::uint16_t command_start_button = 0x4E23;
inline constexpr std::uint16_t command_stop_button = 0x4E24;
/// Clear the alarm and run the next instruction / continue the automatic run.
inline constexpr std::uint16_t command_clear_alarm_next = 0x4E25;
inline constexpr std::uint16_t command_clear_alarm_continue = 0x4E26;
inline constexpr Span command_block{0x4E20, 0x4E26};

// seed 004 3.3.3: output point control, FC16 only: board ID (0-3 IO, 4-6 M, 7 EUIO),
// point 0-31, state 0 / 1 at 0x4E58-0x4E5A.
inline constexpr std::uint16_t output_control = 0x4E58;
// seed 004 3.2.2: global speed, 0-1000 for 0.0-100.0 %.
inline constexpr std::uint16_t global_speed = 0x4EE8;

// State polled for MQTT (seed 004 3.1.5-3.1.15, section 4).
inline constexpr std::uint16_t mode = 0x0889;           ///< 1 manual, 2 auto (3.1.5 example: 3, configuration)
inline constexpr std::uint16_t axis_count = 0x08DB;     ///< 0-8
inline constexpr std::uint16_t axis_positions = 0x08DC; ///< signed 32-bit x1000 deg, high word first, 2 per axis
inline constexpr std::uint16_t world_positions = 0x091C;///< signed 32-bit x1000 mm, X Y Z U V W M7 M8
inline constexpr std::uint16_t alarm_number = 0x095C;
inline constexpr std::uint16_t cycle_current = 0x095D;  ///< ms, unsigned 64-bit, highest word first
inline constexpr std::uint16_t cycle_last = 0x0961;     ///< ms, the last finished cycle ("上模周期")
inline constexpr std::uint16_t move_state = 0x09A6;     ///< 0 stopped, 1 moving
inline constexpr std::uint16_t origin_state = 0x09A7;   ///< 1 when every axis has its origin set
inline constexpr unsigned max_axes = 8;
inline constexpr unsigned world_axes = 8;

}  // namespace fieldbridge::northbound::r6
