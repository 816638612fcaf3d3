#pragma once
/// @file generic_modbus_model.hpp
/// A generic Modbus-RTU slave (type `modbus`): the counterpart of the gateway's
/// generic `modbus` device type, for benchmarks and configurations that are not
/// one of the manuals' devices. Address 1-247, broadcast 0 (acts, never answers).
///
/// Every one of the 65,536 holding registers exists: FC03 reads it, FC06 and FC16
/// write it; each starts at its own address (register 0x0123 reads 0x0123 until
/// written), so a reader can tell which registers it got. FC04 reads the input
/// registers, which always hold their own address. Any other function code: 01.
/// A read or write running past 0xFFFF: 02.

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "models/bus_device.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::sim {

class GenericModbusModel final : public BusDevice {
public:
    /// Throws std::invalid_argument for an address outside 1-247.
    explicit GenericModbusModel(std::uint8_t address);

    [[nodiscard]] BusProtocol protocol() const noexcept override { return BusProtocol::modbus_rtu; }
    [[nodiscard]] std::uint8_t address() const noexcept override { return address_; }
    [[nodiscard]] std::string_view type() const noexcept override { return "modbus"; }
    [[nodiscard]] std::optional<protocol::Bytes> on_frame(protocol::ByteView frame,
                                                          Clock::time_point now) override;
    void advance(Clock::time_point) override {}
    /// No control commands: it has no state beyond its registers.
    [[nodiscard]] std::string control(std::string_view command, Clock::time_point now) override;

private:
    [[nodiscard]] protocol::Response handle(const protocol::Request& request);

    std::uint8_t address_;
    std::vector<std::uint16_t> holding_;
};

[[nodiscard]] std::unique_ptr<BusDevice> make_generic_modbus(std::uint8_t address);

}  // namespace fieldbridge::sim
