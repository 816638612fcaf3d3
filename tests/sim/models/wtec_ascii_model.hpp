#pragma once
/// @file wtec_ascii_model.hpp
/// WTEC-485 gripper in its vendor ASCII mode (seed 003 part 1): every command of the
/// manual (A $ a B b C D d E G g I i P p N n R r U W w Z) through the typed codec of
/// protocol/wtec_ascii_commands.hpp. Addresses 0x01-0xFD, 00 is broadcast: `$` to 00
/// is answered by every device (each from its own address); any other command to 00
/// acts without a reply.
///
/// Behaviour (README.md beside this file):
/// - `D` stores the target and moves there at the `N` speed (position mode): the
///   manual calls it "set the motor's running coordinate", and `N` reads that target
///   back. When not homed, released or e-stopped it only stores the target.
/// - `E` (1 grip, 2 release, 3 toggle) before homing, released or e-stopped is
///   answered with the request itself and does nothing (seed 003 command 9).
/// - `G` homes (answered with the request, as the manual shows); `U` too.
/// - `a0` releases the motor (grip state 11); `a1` enables it unless the e-stop latch
///   of the Modbus face (control "estop") is set.
/// - `Z` calibrates the encoder: the gripper must home again.
/// - A frame that does not decode (unknown letter, wrong data length, bad hex) gets no
///   reply: the protocol has no error answer.

#include <cstdint>
#include <memory>
#include <optional>

#include "models/bus_device.hpp"
#include "models/wtec_gripper.hpp"
#include "protocol/wtec_ascii_commands.hpp"

namespace fieldbridge::sim {

class WtecAsciiModel final : public BusDevice {
public:
    /// Throws std::invalid_argument for an address outside 0x01-0xFD or a stroke
    /// outside 100-10,000,000 counts.
    WtecAsciiModel(std::uint8_t address, std::uint32_t stroke);

    [[nodiscard]] BusProtocol protocol() const noexcept override { return BusProtocol::wtec_ascii; }
    [[nodiscard]] std::uint8_t address() const noexcept override { return address_; }
    [[nodiscard]] std::string_view type() const noexcept override { return "wtec-ascii"; }
    [[nodiscard]] std::optional<protocol::Bytes> on_frame(protocol::ByteView frame,
                                                          Clock::time_point now) override;
    void advance(Clock::time_point now) override { gripper_.advance(now); }
    [[nodiscard]] std::string control(std::string_view command, Clock::time_point now) override;

    [[nodiscard]] const WtecGripper& gripper() const noexcept { return gripper_; }

private:
    std::uint8_t address_;
    WtecGripper gripper_;
};

[[nodiscard]] std::unique_ptr<BusDevice> make_wtec_ascii(std::uint8_t address, std::uint32_t stroke);

}  // namespace fieldbridge::sim
