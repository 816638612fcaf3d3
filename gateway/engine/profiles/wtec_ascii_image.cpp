#include "engine/profiles/wtec_ascii_image.hpp"

#include <array>
#include <initializer_list>

#include "engine/profiles/wtec_ascii_profile.hpp"
#include "engine/profiles/wtec_common.hpp"

namespace fieldbridge::engine::wtec_image {

namespace {

using namespace wtec_reg;
namespace wtec = protocol::wtec;

constexpr std::uint8_t homing_mode_reverse = 0xFC;  // "FC 反向碰撞回零"
constexpr std::uint8_t homing_mode_forward = 0xFD;  // "FD 为正向碰撞回零"

[[nodiscard]] std::uint16_t high(std::uint32_t v) noexcept { return static_cast<std::uint16_t>(v >> 16); }
[[nodiscard]] std::uint16_t low(std::uint32_t v) noexcept { return static_cast<std::uint16_t>(v & 0xFFFFU); }

void put(RegisterImage& image, Table table, std::uint16_t address, std::initializer_list<std::uint16_t> values,
         TimePoint now) {
    image.update(table, address, std::span<const std::uint16_t>(values.begin(), values.size()), now);
}

void put_input(RegisterImage& image, std::uint16_t address, std::initializer_list<std::uint16_t> values,
               TimePoint now) {
    put(image, Table::input, address, values, now);
}

void put_holding(RegisterImage& image, std::uint16_t address, std::uint16_t value, TimePoint now) {
    put(image, Table::holding, address, {value}, now);
}

/// Force 0x0103 = N max (grip) current as a share of R max current (seed 003 table
/// 2.5: "the maximum running current set over ASCII is the current at 100 %").
void refresh_force(RegisterImage& image, TimePoint now) {
    const auto current = image.value(Table::input, ext_n_current);
    const auto full = max_current_in(image);
    if (current && full) {
        put_holding(image, force, wtec_force_percent(*current, *full), now);
    }
}

}  // namespace

std::optional<std::uint32_t> u32_in(const RegisterImage& image, std::uint16_t address) {
    const auto h = image.value(Table::input, address);
    const auto l = image.value(Table::input, static_cast<std::uint16_t>(address + 1));
    if (!h || !l) {
        return std::nullopt;
    }
    return (std::uint32_t{*h} << 16) | *l;
}

void store_running(RegisterImage& image, const wtec::RunningValues& values, std::uint32_t stroke, TimePoint now) {
    const auto raw = static_cast<std::uint32_t>(values.position);
    put_input(image, ext_position,
              {high(raw), low(raw), values.current, static_cast<std::uint16_t>(values.enabled ? 1 : 0), values.state},
              now);
    put_holding(image, grip_state, wtec_uniform_grip_state(values.state), now);
    // Seed 003 command 12 example: -3 counts when released to the open limit; a
    // position before the homing point reads 0.
    put_holding(image, instant_position, wtec_raw_to_percent(values.position, stroke), now);
}

void store_grip_code(RegisterImage& image, std::uint8_t code, TimePoint now) {
    put_input(image, ext_grip_code, {code}, now);
    put_holding(image, grip_state, wtec_uniform_grip_state(code), now);
}

void store_homing_code(RegisterImage& image, std::uint8_t code, TimePoint now) {
    put_input(image, ext_homing_code, {code}, now);
    put_holding(image, init_state, wtec_uniform_init_state(code), now);
}

void store_gripper(RegisterImage& image, const wtec::GripperParams& params, std::uint32_t stroke, TimePoint now) {
    put_input(image, ext_n_target,
              {high(params.target), low(params.target), params.max_current, params.speed, params.confirm_time,
               params.home_at_power_up},
              now);
    put_holding(image, speed, wtec_raw_to_percent(params.speed, 0xFF), now);
    // 0x0105 shows the target the gripper was last sent, as the RTU mode's register
    // does. `D` moves without changing N's target parameter, so N fills 0x0105 only
    // until the first acknowledged `D`; after that N refreshes what `D` left.
    const std::optional<std::uint16_t> sent = image.value(Table::holding, position);
    put_holding(image, position,
                sent ? *sent : wtec_raw_to_percent(static_cast<std::int32_t>(params.target), stroke), now);
    refresh_force(image, now);
}

void store_peak_current(RegisterImage& image, std::uint8_t current, TimePoint now) {
    put_input(image, ext_n_current, {current}, now);
    refresh_force(image, now);
}

void store_target(RegisterImage& image, std::int32_t target, std::uint32_t stroke, TimePoint now) {
    // N's target (0x1006) is the device's parameter, which `D` does not change.
    put_holding(image, position, wtec_raw_to_percent(target, stroke), now);
}

void store_driver(RegisterImage& image, const wtec::DriverParams& p, TimePoint now) {
    put_input(image, ext_r_max_speed,
              {high(p.max_speed), low(p.max_speed), high(p.max_acceleration), low(p.max_acceleration), p.max_current,
               p.damping, p.program, p.mode, p.pulses_per_revolution, high(p.following_error),
               low(p.following_error), p.multi_turn},
              now);
    refresh_force(image, now);
}

void store_homing(RegisterImage& image, const wtec::HomingParams& p, TimePoint now) {
    put_input(image, ext_b_mode,
              {p.mode, high(p.speed), low(p.speed), high(p.acceleration), low(p.acceleration), high(p.offset),
               low(p.offset), p.current, p.sensor_mode, high(p.confirm_time), low(p.confirm_time),
               high(p.max_distance), low(p.max_distance)},
              now);
    // FC (reverse collision homing) is the manual's example and default, and the
    // RTU mode's default direction is 1 (open, table 2.9); the `I` example reads
    // about 0 counts when released to the open limit: FC homes at the open end.
    const std::uint16_t direction = p.mode == homing_mode_reverse   ? direction_open
                                    : p.mode == homing_mode_forward ? direction_close
                                                                    : p.mode;
    put_holding(image, init_direction, direction, now);
}

void store_version(RegisterImage& image, const std::string& text, TimePoint now) {
    std::array<std::uint16_t, ext_firmware_registers> regs{};
    for (std::size_t i = 0; i < text.size() && i < regs.size() * 2; ++i) {
        const auto c = static_cast<std::uint8_t>(text[i]);
        regs[i / 2] = static_cast<std::uint16_t>(regs[i / 2] | (i % 2 == 0 ? c << 8 : c));
    }
    image.update(Table::input, ext_firmware, regs, now);
}

void store_pid(RegisterImage& image, const wtec::Pid& pid, TimePoint now) {
    put_input(image, ext_pid, {pid.p, pid.i, pid.d}, now);
}

void store_release(RegisterImage& image, const wtec::ReleaseParams& params, TimePoint now) {
    put_input(image, ext_release, {params.current, params.speed}, now);
}

std::optional<wtec::GripperParams> gripper_in(const RegisterImage& image) {
    const auto target = u32_in(image, ext_n_target);
    const auto current = image.value(Table::input, ext_n_current);
    const auto spd = image.value(Table::input, ext_n_speed);
    const auto confirm = image.value(Table::input, ext_n_confirm);
    const auto home = image.value(Table::input, ext_n_home_at_power_up);
    if (!target || !current || !spd || !confirm || !home) {
        return std::nullopt;
    }
    return wtec::GripperParams{*target, static_cast<std::uint8_t>(*current), static_cast<std::uint8_t>(*spd),
                               static_cast<std::uint8_t>(*confirm), static_cast<std::uint8_t>(*home)};
}

std::optional<wtec::HomingParams> homing_in(const RegisterImage& image) {
    const auto mode = image.value(Table::input, ext_b_mode);
    const auto spd = u32_in(image, ext_b_speed);
    const auto accel = u32_in(image, ext_b_accel);
    const auto offset = u32_in(image, ext_b_offset);
    const auto current = image.value(Table::input, ext_b_current);
    const auto sensor = image.value(Table::input, ext_b_sensor);
    const auto confirm = u32_in(image, ext_b_confirm);
    const auto distance = u32_in(image, ext_b_max_distance);
    if (!mode || !spd || !accel || !offset || !current || !sensor || !confirm || !distance) {
        return std::nullopt;
    }
    return wtec::HomingParams{static_cast<std::uint8_t>(*mode), *spd, *accel, *offset,
                              static_cast<std::uint8_t>(*current), static_cast<std::uint8_t>(*sensor),
                              *confirm, *distance};
}

std::optional<std::uint8_t> max_current_in(const RegisterImage& image) {
    const auto v = image.value(Table::input, ext_r_max_current);
    if (!v || *v == 0) {
        return std::nullopt;
    }
    return static_cast<std::uint8_t>(*v);
}

}  // namespace fieldbridge::engine::wtec_image
