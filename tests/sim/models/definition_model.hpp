#pragma once
/// @file definition_model.hpp
/// A Modbus-RTU slave simulated from a device definition (docs/devices.md): it has
/// exactly the registers (and coils) its points and blocks name, in the four tables,
/// each starting at 0. FC01-06, FC15, FC16 and FC22 read and write them; a request
/// that touches any address the definition does not name answers 02, as a real device
/// that lacks the register; other function codes 01. Writes are taken as they come
/// (no writable / min / max here: those are the gateway's checks). Address 1-247,
/// broadcast 0 (writes act, nothing answers).
///
/// Control: `set POINT VALUE` (engineering units, an enum label, true / false, or
/// the text of a string point) and `set-register TABLE ADDRESS VALUE...` (raw
/// values from ADDRESS on; 0 / 1 for coils and discrete inputs).

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/point.hpp"
#include "models/bus_device.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::sim {

/// Addresses of one table a definition's block names.
struct TableSpan {
    core::RegisterTable table = core::RegisterTable::holding;
    std::uint16_t address = 0;
    std::uint16_t count = 0;
};

/// What the simulator needs of a definition.
struct DefinitionSpec {
    std::string name;  ///< the definition's name: the device's type in logs
    core::PointModel points;
    std::vector<TableSpan> blocks;
};

class DefinitionModel final : public BusDevice {
public:
    /// Throws std::invalid_argument for an address outside 1-247.
    DefinitionModel(std::uint8_t address, std::shared_ptr<const DefinitionSpec> spec);

    [[nodiscard]] BusProtocol protocol() const noexcept override { return BusProtocol::modbus_rtu; }
    [[nodiscard]] std::uint8_t address() const noexcept override { return address_; }
    [[nodiscard]] std::string_view type() const noexcept override { return spec_->name; }
    [[nodiscard]] std::optional<protocol::Bytes> on_frame(protocol::ByteView frame, Clock::time_point now) override;
    void advance(Clock::time_point) override {}
    [[nodiscard]] std::string control(std::string_view command, Clock::time_point now) override;

    /// The raw value at @p address of @p table (0 when the definition lacks it).
    [[nodiscard]] std::uint16_t value(core::RegisterTable table, std::uint16_t address) const noexcept;

private:
    struct Table {
        std::vector<bool> present = std::vector<bool>(0x10000);
        std::vector<std::uint16_t> values = std::vector<std::uint16_t>(0x10000);
        /// Every address of [address, address + count) is present.
        [[nodiscard]] bool has(std::size_t address, std::size_t count) const noexcept;
    };
    [[nodiscard]] protocol::Response handle(const protocol::Request& request);
    [[nodiscard]] std::string set_point(std::string_view name, std::string_view text);
    [[nodiscard]] std::string set_register(std::string_view args);
    [[nodiscard]] Table& table(core::RegisterTable t) noexcept { return tables_[static_cast<std::size_t>(t)]; }

    std::uint8_t address_;
    std::shared_ptr<const DefinitionSpec> spec_;
    std::array<Table, core::table_count> tables_;
};

}  // namespace fieldbridge::sim
