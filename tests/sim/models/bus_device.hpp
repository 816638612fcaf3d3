#pragma once
/// @file bus_device.hpp
/// A simulated device on a simulated serial bus. Models are pure: they see complete
/// request frames and the (simulated) time, and return the reply bytes they would
/// put on the wire. The bus runtime owns framing, timing, faults and the pty.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "protocol/bytes.hpp"

namespace fieldbridge::sim {

using Clock = std::chrono::steady_clock;

enum class BusProtocol : std::uint8_t { modbus_rtu, wtec_ascii };

class BusDevice {
public:
    virtual ~BusDevice() = default;
    BusDevice() = default;
    BusDevice(const BusDevice&) = delete;
    BusDevice& operator=(const BusDevice&) = delete;

    [[nodiscard]] virtual BusProtocol protocol() const noexcept = 0;
    /// Current bus address (it can change: WTEC `i`, WTEC RTU 0x0303).
    [[nodiscard]] virtual std::uint8_t address() const noexcept = 0;
    /// Short type name for logs and control commands ("hiwin-xeg", "excd203mb",
    /// "wtec-rtu", "wtec-ascii").
    [[nodiscard]] virtual std::string_view type() const noexcept = 0;

    /// A complete, CRC-valid frame seen on the bus: an RTU ADU (address + PDU + CRC)
    /// or a WTEC ASCII frame including '>' and CR LF. The device checks whether it
    /// is addressed (its address or a broadcast it listens to). Returns the full
    /// reply bytes (RTU ADU with CRC, or ASCII frame with CR LF), or nullopt when it
    /// does not answer (not addressed, broadcast).
    [[nodiscard]] virtual std::optional<protocol::Bytes> on_frame(protocol::ByteView frame,
                                                                  Clock::time_point now) = 0;

    /// Advances motion to @p now (called before every frame and periodically).
    virtual void advance(Clock::time_point now) = 0;

    /// Test/demo control, e.g. "alarm 5", "clear", "object 12.5" (grip an object at
    /// that width), "estop". Returns an error text, or empty on success.
    [[nodiscard]] virtual std::string control(std::string_view command, Clock::time_point now) = 0;
};

}  // namespace fieldbridge::sim
