#pragma once
/// @file wtec_rtu_model.hpp
/// WTEC-485 gripper in Modbus-RTU mode (seed 003 part 2): FC03 and FC06 only
/// (others: 01). Address 1-247 (default 1), broadcast 0 (acts, never answers).
///
/// | register | read                                    | FC06 write                         |
/// |----------|-----------------------------------------|------------------------------------|
/// | 0x0100   | 0                                       | 1: initialize (home)               |
/// | 0x0102   | e-stop latch 0/1                        | 1: e-stop (cleared by 0x0100 only) |
/// | 0x0103   | force: N max / R max current, %         | 20-100: N max = % x R max / 100    |
/// | 0x0104   | speed 1-100 %                           | 1-100                              |
/// | 0x0105   | set position 0-100 (target / stroke)    | 0-100: move there (0 = homing end) |
/// | 0x0200   | init state 0 no, 1 done, 2 failed, 9 busy| -                                 |
/// | 0x0202   | grip state 0 moving, 1 reached, 2 gripped, 11 released / not homed | -       |
/// | 0x0204   | instant position 0-100                  | -                                  |
/// | 0x0300   | init direction 1 open, 2 closed         | 1-2                                |
/// | 0x0302   | saved flag 0/1                          | 0-1 (1: save to flash)             |
/// | 0x0303   | device id                               | 1-247: the reply comes from the new id |
///
/// Reads inside the blocks 0x0100-0x0105, 0x0200-0x0205 and 0x0300-0x0303 return 0 for
/// the addresses the manual does not define; anything else is 02. A write to an address
/// without a write meaning is 02, a value out of range 03, a position while not
/// initialized, released or e-stopped 04. Grip state 11 is the decimal number 11 (the
/// ASCII code 0x11), as seed 003 table 2.8 prints it.

#include <cstdint>
#include <memory>
#include <optional>

#include "models/bus_device.hpp"
#include "models/wtec_gripper.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::sim {

class WtecRtuModel final : public BusDevice {
public:
    /// Throws std::invalid_argument for an address outside 1-247 or a stroke outside
    /// 100-10,000,000 counts.
    WtecRtuModel(std::uint8_t address, std::uint32_t stroke);

    [[nodiscard]] BusProtocol protocol() const noexcept override { return BusProtocol::modbus_rtu; }
    [[nodiscard]] std::uint8_t address() const noexcept override { return address_; }
    [[nodiscard]] std::string_view type() const noexcept override { return "wtec-rtu"; }
    [[nodiscard]] std::optional<protocol::Bytes> on_frame(protocol::ByteView frame,
                                                          Clock::time_point now) override;
    void advance(Clock::time_point now) override { gripper_.advance(now); }
    [[nodiscard]] std::string control(std::string_view command, Clock::time_point now) override;

    [[nodiscard]] const WtecGripper& gripper() const noexcept { return gripper_; }

private:
    [[nodiscard]] protocol::Response read(const protocol::ReadRegistersRequest& request) const;
    [[nodiscard]] protocol::Response write(const protocol::WriteSingleRegisterRequest& request,
                                           Clock::time_point now);
    [[nodiscard]] std::optional<std::uint16_t> register_value(std::uint16_t address) const;

    std::uint8_t address_;
    WtecGripper gripper_;
};

/// Map of the ASCII `g` code to register 0x0200 and of the `d` code to 0x0202 (the
/// uniform register view of the spec, section 5).
[[nodiscard]] std::uint16_t wtec_init_state_register(std::uint8_t homing_code) noexcept;
[[nodiscard]] std::uint16_t wtec_grip_state_register(std::uint8_t grip_code) noexcept;
/// Position in counts -> 0-100 % of @p stroke, rounded, clamped.
[[nodiscard]] std::uint16_t wtec_percent_of(std::int64_t counts, std::uint32_t stroke) noexcept;

[[nodiscard]] std::unique_ptr<BusDevice> make_wtec_rtu(std::uint8_t address, std::uint32_t stroke);

}  // namespace fieldbridge::sim
