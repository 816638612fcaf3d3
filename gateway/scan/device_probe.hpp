#pragma once
/// @file device_probe.hpp
/// What the line scan asks a bus address and what it concludes from the answers.
/// Pure: requests out, replies in, no port and no clock (the LineScanner drives it
/// through the line master).
///
/// Modbus-RTU, per address (ModbusProbe):
///  1. presence: FC03, one holding register at 0x0000. Any valid reply, an exception
///     included, means a device listens at that address; no reply ends the probe.
///  2. HIWIN XEG: FC03 0x0600 (the gripper model, seed 001 section 3.3) reads one of
///     the listed model codes (0x0A10 XEG-16 ... 0x0A40 XEG-64).
///  3. WTEC-485 in RTU mode: FC03 0x0303 (device ID, seed 003 table 2.11) reads the
///     address the device answered from.
///  4. EXCD203MB: FC03 0x0207-0x0208 (`ver`, a 32-bit query register of seed 002
///     section 4) is answered with two registers.
///  5. anything else is a generic Modbus device.
/// Every request is a read: nothing a scan sends can move or reconfigure a device.
///
/// WTEC-485 ASCII: `$` (read all stations, seed 003 command 2) goes to address 00
/// and every ASCII device answers from its own address; parse_stations() reads the
/// replies, and each station is confirmed with `A` (read the firmware version).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "engine/profiles/device_profile.hpp"
#include "protocol/bytes.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::scan {

/// A device the scan found.
struct FoundDevice {
    std::uint8_t address = 0;
    engine::DeviceType type = engine::DeviceType::modbus;
    /// What identified it, for the snippet's comment: "XEG-32 (model 0x0A20)".
    std::string detail;
    /// modbus only: holding register 0x0000 answered with a value (so a block there
    /// is known to be readable).
    bool holding_zero_readable = false;
    bool operator==(const FoundDevice&) const = default;
};

/// The identification sequence of one Modbus-RTU address.
class ModbusProbe {
public:
    explicit ModbusProbe(std::uint8_t address);

    /// The read to send next; nullopt when the probe is finished.
    [[nodiscard]] std::optional<protocol::Request> next() const;
    /// The reply to the request next() gave; nullopt when none came in time.
    /// Precondition: next() has a value (throws std::logic_error otherwise).
    void on_reply(const std::optional<protocol::Response>& reply);

    [[nodiscard]] bool finished() const noexcept { return step_ == Step::finished; }
    /// After finished(): the device, or nullopt when nothing answered.
    [[nodiscard]] const std::optional<FoundDevice>& result() const noexcept { return found_; }

private:
    enum class Step : std::uint8_t { presence, xeg_model, wtec_id, excd_version, finished };

    void identified(engine::DeviceType type, std::string detail);

    std::uint8_t address_;
    Step step_ = Step::presence;
    bool holding_zero_readable_ = false;
    std::optional<FoundDevice> found_;
};

/// The stations named by every valid `$` reply in @p rx (bytes that arrived after the
/// query, several frames possible, noise skipped), ascending and without duplicates.
[[nodiscard]] std::vector<std::uint8_t> parse_stations(protocol::ByteView rx);

}  // namespace fieldbridge::scan
