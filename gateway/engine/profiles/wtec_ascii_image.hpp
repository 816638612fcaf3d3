#pragma once
/// @file wtec_ascii_image.hpp
/// How WTEC ASCII replies land in the uniform register view and its extension
/// block, and how the parameters the write translations need are read back from
/// the image. Used by WtecAsciiProfile only.

#include <cstdint>
#include <optional>
#include <string>

#include "engine/register_image.hpp"
#include "protocol/wtec_ascii_commands.hpp"

namespace fieldbridge::engine::wtec_image {

/// `I`: raw position, current, enable and state code (extension), grip state
/// (0x0202) and instant position (0x0204).
void store_running(RegisterImage& image, const protocol::wtec::RunningValues& values, std::uint32_t stroke,
                   TimePoint now);
/// `d`: raw grip code and 0x0202.
void store_grip_code(RegisterImage& image, std::uint8_t code, TimePoint now);
/// `g`: raw homing code and 0x0200.
void store_homing_code(RegisterImage& image, std::uint8_t code, TimePoint now);
/// `N` (or an acknowledged `n`): extension fields, speed 0x0104, force 0x0103 when
/// R is known, and position 0x0105 from N's target until an acknowledged `D` has set
/// it (then N only refreshes it: `D` does not change N's target parameter).
void store_gripper(RegisterImage& image, const protocol::wtec::GripperParams& params, std::uint32_t stroke,
                   TimePoint now);
/// An acknowledged `C`: the grip current, i.e. N max current, and force 0x0103.
void store_peak_current(RegisterImage& image, std::uint8_t current, TimePoint now);
/// An acknowledged `D`: position 0x0105, the target last sent.
void store_target(RegisterImage& image, std::int32_t target, std::uint32_t stroke, TimePoint now);
/// `R`: extension fields and force 0x0103 when N is known.
void store_driver(RegisterImage& image, const protocol::wtec::DriverParams& params, TimePoint now);
/// `B` (or an acknowledged `b`): extension fields and init direction 0x0300.
void store_homing(RegisterImage& image, const protocol::wtec::HomingParams& params, TimePoint now);
/// `A`: the text, two characters per register (first in the high byte), NUL padded.
void store_version(RegisterImage& image, const std::string& text, TimePoint now);
void store_pid(RegisterImage& image, const protocol::wtec::Pid& pid, TimePoint now);
void store_release(RegisterImage& image, const protocol::wtec::ReleaseParams& params, TimePoint now);

/// N as last read (every field present), for `n`.
[[nodiscard]] std::optional<protocol::wtec::GripperParams> gripper_in(const RegisterImage& image);
/// B as last read (every field present), for `b`.
[[nodiscard]] std::optional<protocol::wtec::HomingParams> homing_in(const RegisterImage& image);
/// R's max current when read and not 0 (the current at 100 % force).
[[nodiscard]] std::optional<std::uint8_t> max_current_in(const RegisterImage& image);
/// A pair of extension registers, high word first.
[[nodiscard]] std::optional<std::uint32_t> u32_in(const RegisterImage& image, std::uint16_t address);

}  // namespace fieldbridge::engine::wtec_image
