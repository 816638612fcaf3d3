#pragma once
/// @file wtec_common.hpp
/// The WTEC-485 uniform register map (seed 003 part 2, "Modbus-RTU" table 2.2),
/// shared by the WTEC Modbus-RTU profile and the ASCII view, so that a PLC sees the
/// same registers whichever mode the gripper is in (spec §5). All are holding
/// registers. The ASCII view adds an extension block of input registers from
/// 0x1000 (docs/registers.md).

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "engine/profiles/device_profile.hpp"
#include "engine/profiles/register_map.hpp"

namespace fieldbridge::engine::wtec_reg {

// Holding registers (seed 003 table 2.2).
inline constexpr std::uint16_t initialize = 0x0100;        ///< write 1: home (write-only)
inline constexpr std::uint16_t estop = 0x0102;             ///< write 1: e-stop; reads 0 / 1
inline constexpr std::uint16_t force = 0x0103;             ///< 20-100 %
inline constexpr std::uint16_t speed = 0x0104;             ///< 1-100 %
inline constexpr std::uint16_t position = 0x0105;          ///< 0-100: move there (reads the target)
inline constexpr std::uint16_t init_state = 0x0200;        ///< 0 / 1 / 2 / 9 (read-only)
inline constexpr std::uint16_t grip_state = 0x0202;        ///< 0 / 1 / 2 / 11 (read-only)
inline constexpr std::uint16_t instant_position = 0x0204;  ///< 0-100 (read-only)
inline constexpr std::uint16_t init_direction = 0x0300;    ///< 1 open, 2 close
inline constexpr std::uint16_t save = 0x0302;              ///< write 1: save to flash (protected)
inline constexpr std::uint16_t device_id = 0x0303;         ///< Modbus ID (protected)

// Values.
inline constexpr std::uint16_t init_not_done = 0;
inline constexpr std::uint16_t init_done = 1;
inline constexpr std::uint16_t init_failed = 2;
inline constexpr std::uint16_t init_running = 9;
inline constexpr std::uint16_t grip_moving = 0;
inline constexpr std::uint16_t grip_reached = 1;
inline constexpr std::uint16_t grip_gripped = 2;
/// "11: 未回零释能" (table 2.8), read as decimal 11.
inline constexpr std::uint16_t grip_released = 11;
/// The same state if a firmware copies the ASCII code 0x11 into the register.
inline constexpr std::uint16_t grip_released_hex = 0x11;
inline constexpr std::uint16_t direction_open = 1;
inline constexpr std::uint16_t direction_close = 2;

// ASCII view extension block: input registers (docs/registers.md).
inline constexpr std::uint16_t ext_position = 0x1000;      ///< I: signed 32-bit, 2 registers, high first
inline constexpr std::uint16_t ext_current = 0x1002;       ///< I: current
inline constexpr std::uint16_t ext_enabled = 0x1003;       ///< I: enable 0 / 1
inline constexpr std::uint16_t ext_grip_code = 0x1004;     ///< I / d: raw grip state code
inline constexpr std::uint16_t ext_homing_code = 0x1005;   ///< g: raw homing state code
inline constexpr std::uint16_t ext_n_target = 0x1006;      ///< N: target, 2 registers
inline constexpr std::uint16_t ext_n_current = 0x1008;     ///< N: max (grip) current
inline constexpr std::uint16_t ext_n_speed = 0x1009;       ///< N: speed 0-255
inline constexpr std::uint16_t ext_n_confirm = 0x100A;     ///< N: confirm time
inline constexpr std::uint16_t ext_n_home_at_power_up = 0x100B;
inline constexpr std::uint16_t ext_r_max_speed = 0x100C;   ///< R: 2 registers
inline constexpr std::uint16_t ext_r_max_accel = 0x100E;   ///< R: 2 registers
inline constexpr std::uint16_t ext_r_max_current = 0x1010; ///< R: current at 100 % force
inline constexpr std::uint16_t ext_r_damping = 0x1011;
inline constexpr std::uint16_t ext_r_program = 0x1012;
inline constexpr std::uint16_t ext_r_mode = 0x1013;
inline constexpr std::uint16_t ext_r_pulses = 0x1014;      ///< R: pulses per revolution
inline constexpr std::uint16_t ext_r_ferror = 0x1015;      ///< R: following error, 2 registers
inline constexpr std::uint16_t ext_r_multi_turn = 0x1017;
inline constexpr std::uint16_t ext_b_mode = 0x1018;        ///< B: 0xFC / 0xFD
inline constexpr std::uint16_t ext_b_speed = 0x1019;       ///< B: 2 registers
inline constexpr std::uint16_t ext_b_accel = 0x101B;       ///< B: 2 registers
inline constexpr std::uint16_t ext_b_offset = 0x101D;      ///< B: 2 registers
inline constexpr std::uint16_t ext_b_current = 0x101F;
inline constexpr std::uint16_t ext_b_sensor = 0x1020;
inline constexpr std::uint16_t ext_b_confirm = 0x1021;     ///< B: 2 registers
inline constexpr std::uint16_t ext_b_max_distance = 0x1023;  ///< B: 2 registers
inline constexpr std::uint16_t ext_pid = 0x1025;           ///< P: P, I, D (3 registers)
inline constexpr std::uint16_t ext_release = 0x1028;       ///< W: release current, speed (2 registers)
inline constexpr std::uint16_t ext_firmware = 0x102A;      ///< A: up to 16 characters, 2 per register
inline constexpr std::uint16_t ext_firmware_registers = 8;
inline constexpr std::uint16_t ext_end = 0x1032;           ///< one past the last extension register

}  // namespace fieldbridge::engine::wtec_reg

namespace fieldbridge::engine {

/// The MQTT operations of both modes (docs/mqtt.md, "wtec-rtu and wtec-ascii"): init,
/// grip, release, position, force, speed, estop on the uniform map. grip and release
/// read the init direction (0x0300) from the registers they are given.
[[nodiscard]] OperationSet wtec_operations();
/// The state fields an op of wtec_operations() sets alone: target_pct (position),
/// force_pct (force), speed_pct (speed).
[[nodiscard]] std::span<const FieldSetter> wtec_field_setters() noexcept;

/// Rule 5: moving (grip state 0) or homing (init state 9).
[[nodiscard]] bool wtec_in_motion(const RegisterImage& image);

}  // namespace fieldbridge::engine
