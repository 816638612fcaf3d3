#pragma once
/// @file xeg_model.hpp
/// HIWIN XEG-C2 electric gripper controller (seed 001), Modbus-RTU slave.
///
/// Map (seed 001 section 3): FC02 discrete inputs 0x0000-0x0007 (IN1..IN6, START) and
/// 0x0010-0x0017 (POS, HOLD, BUSY, ALM1, ALM2, CHK1..CHK3); FC04 input registers 0x0300
/// position (0.01 mm), 0x0301 status 0-7, 0x0303-0x0306 firmware V3.0.1.884; FC03/FC10
/// holding registers 0x0600 model, 0x0601 trigger, 0x0610 reset, 0x0620 stop,
/// 0x0630-0x0632 move, 0x0640-0x0646 expert; FC07 exception status. Broadcast address 0:
/// FC10 acts, nothing answers.
///
/// Exceptions (seed 001 section 5): 01 for a function code the controller lacks
/// (FC06 to an address of the map too: the function table lists 02/03/04/07/10 only),
/// 02 for an address outside the map (FC06 to 0x0611 -> 02, the manual's example), 03
/// for values outside the model's range (section 3.4.2 table), 04 when the command
/// cannot run (not reset yet, busy, alarm, wrong gripper type): FC07 then tells why.
///
/// Position is the jaw opening: reset homes to the open end (the model's full stroke).
/// Choices where the manual is silent (documented in README.md beside this file):
/// - reset travels at 10.00 mm/s (under 7 s for any model, the manual waits 30 s);
/// - a closing Move that meets an object stops there with status 5 (Move alarm), as
///   section 3.4.2 says for obstacles; a closing Expert holds it (status 3);
/// - an Expert stroke past either end stops at the end with status 4;
/// - DO ALM1 is on for the motion alarms (status 4-6), ALM2 for the emergency stop
///   (status 7); CHK1-CHK3 are not defined by the manual and stay off;
/// - indirect data n (0x0601 = 1..63) moves to n/63 of the stroke at the model's
///   maximum speed (the real data table is set up with HIWIN's software).
///
/// Control commands: "alarm 4".."alarm 7", "clear", "object <mm>" (an object of that
/// width between the jaws, e.g. "object 20.0"), "object none", "inputs <mask>" (DI
/// 0x0000-0x0007, e.g. "inputs 0x22").

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "models/bus_device.hpp"
#include "models/linear_move.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::sim {

struct XegOptions {
    /// Model code of the connected gripper (0x0A10, 0x0A20, 0x0A21, 0x0A30, 0x0A40).
    std::uint16_t model = 0x0A20;
};

/// Ranges of one XEG model, seed 001 section 3.4.2 (units 0.01 mm, 0.01 mm/s, %).
struct XegSpec {
    std::uint16_t code = 0;
    std::int64_t stroke = 0;
    std::int64_t max_speed = 0;
    std::int64_t max_hold_speed = 0;
    std::int64_t min_force = 0;
};

/// The spec of a model code, or nullopt for a code the manual does not list.
[[nodiscard]] std::optional<XegSpec> xeg_spec(std::uint16_t code) noexcept;

/// Exception status codes of FC07 (seed 001 section 4.2.4).
namespace xeg_exception_status {
inline constexpr std::uint8_t idle = 0x00;
inline constexpr std::uint8_t emergency_stop = 0x02;
inline constexpr std::uint8_t address_fail = 0x03;
inline constexpr std::uint8_t type_null = 0x04;
inline constexpr std::uint8_t reset_fail = 0x05;
inline constexpr std::uint8_t stop_fail = 0x06;
inline constexpr std::uint8_t move_null = 0x07;
inline constexpr std::uint8_t expert_null = 0x08;
inline constexpr std::uint8_t move_error = 0x10;
inline constexpr std::uint8_t over_error = 0x11;
inline constexpr std::uint8_t reset_error = 0x12;
}  // namespace xeg_exception_status

/// Gripper status of input register 0x0301 (seed 001 section 3.2).
enum class XegStatus : std::uint16_t {
    idle = 0,
    working = 1,
    positioned = 2,
    holding = 3,
    position_alarm = 4,
    move_alarm = 5,
    home_alarm = 6,
    emergency_stop = 7,
};

class XegModel final : public BusDevice {
public:
    /// Throws std::invalid_argument for an address outside 1-15 (seed 001 section 2.2)
    /// or a model code the manual does not list.
    XegModel(std::uint8_t address, XegOptions options);

    [[nodiscard]] BusProtocol protocol() const noexcept override { return BusProtocol::modbus_rtu; }
    [[nodiscard]] std::uint8_t address() const noexcept override { return address_; }
    [[nodiscard]] std::string_view type() const noexcept override { return "hiwin-xeg"; }
    [[nodiscard]] std::optional<protocol::Bytes> on_frame(protocol::ByteView frame,
                                                          Clock::time_point now) override;
    void advance(Clock::time_point now) override;
    [[nodiscard]] std::string control(std::string_view command, Clock::time_point now) override;

    /// Current state, for tests and the simulator's status output.
    [[nodiscard]] XegStatus status() const noexcept { return status_; }
    [[nodiscard]] std::int64_t position() const noexcept { return position_; }

private:
    /// One leg of a motion: where it goes and what reaching its end (or an object) means.
    enum class Leg : std::uint8_t { homing, move, expert_fast, expert_hold };
    struct Segment {
        Leg leg = Leg::move;
        LinearMove motion;
        bool meets_object = false;  ///< ends at the object instead of its target
        bool hits_end = false;      ///< the target was past an end of the stroke
    };

    // Modbus map (xeg_model.cpp).
    [[nodiscard]] protocol::Response handle(const protocol::Request& request, bool broadcast,
                                            Clock::time_point now);
    [[nodiscard]] protocol::Response read_bits(const protocol::ReadBitsRequest& request) const;
    [[nodiscard]] protocol::Response read_input_registers(const protocol::ReadRegistersRequest& request) const;
    [[nodiscard]] protocol::Response read_holding(const protocol::ReadRegistersRequest& request) const;
    [[nodiscard]] protocol::Response write_holding(const protocol::WriteMultipleRegistersRequest& request,
                                                   Clock::time_point now);
    [[nodiscard]] std::optional<protocol::ExceptionCode> check_value(std::uint16_t address,
                                                                     std::uint16_t value) const;
    [[nodiscard]] std::uint8_t discrete_bits() const noexcept;

    // Motion (xeg_motion.cpp). Each returns the FC07 status code when it cannot run.
    [[nodiscard]] std::optional<std::uint8_t> start_reset(Clock::time_point now);
    [[nodiscard]] std::optional<std::uint8_t> start_move(std::int64_t target, std::int64_t speed,
                                                         Clock::time_point now);
    [[nodiscard]] std::optional<std::uint8_t> start_expert(Clock::time_point now);
    [[nodiscard]] std::optional<std::uint8_t> start_indirect(std::uint16_t data, Clock::time_point now);
    [[nodiscard]] std::optional<std::uint8_t> motion_refusal(std::uint8_t command_code) const noexcept;
    void stop_motion(Clock::time_point now);
    void enqueue(Leg leg, Clock::time_point start, std::int64_t target, std::int64_t speed);
    void finish(const Segment& segment);
    void raise_alarm(XegStatus alarm);
    [[nodiscard]] const XegSpec& spec() const noexcept { return spec_; }

    std::uint8_t address_;
    XegSpec connected_;  ///< the gripper on the cable (option)
    XegSpec spec_;       ///< the model written to 0x0600 (ranges checked against it)
    std::uint16_t model_register_;

    XegStatus status_ = XegStatus::idle;
    std::int64_t position_ = 0;  ///< jaw opening, 0.01 mm
    bool homed_ = false;
    std::uint8_t exception_status_ = xeg_exception_status::idle;
    std::vector<Segment> segments_;  ///< current leg first
    Clock::time_point last_advance_{};

    std::uint16_t move_target_ = 0;
    std::uint16_t move_speed_ = 0;
    /// 0x0640-0x0645: direction, stroke, speed, hold stroke, hold speed, force.
    std::array<std::uint16_t, 6> expert_{};

    std::optional<std::int64_t> object_width_;  ///< 0.01 mm
    std::uint8_t inputs_ = 0;                    ///< IN1..IN6, START
};

[[nodiscard]] std::unique_ptr<BusDevice> make_xeg(std::uint8_t address, XegOptions options);

}  // namespace fieldbridge::sim
