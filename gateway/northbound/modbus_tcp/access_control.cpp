// Request scope for access rules. Field offsets: Modbus Application Protocol
// V1.1b3 section 6 (request PDUs of FC01-06, 0F, 10, 17).
#include "northbound/modbus_tcp/access_control.hpp"

#include <algorithm>

#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::northbound::modbus_tcp {
namespace {

/// [address, address + quantity - 1], at least the addressed register, at most up
/// to 0xFFFF.
[[nodiscard]] config::RegisterRange span(std::uint16_t address, std::uint16_t quantity) noexcept {
    const std::uint32_t last = std::min<std::uint32_t>(
        0xFFFFU, static_cast<std::uint32_t>(address) + std::max<std::uint32_t>(quantity, 1U) - 1U);
    return config::RegisterRange{address, static_cast<std::uint16_t>(last)};
}

// Offsets inside the PDU (function code at 0).
constexpr std::size_t address_offset = 1;
constexpr std::size_t quantity_offset = 3;
constexpr std::size_t address_and_quantity_size = 5;  // fc + address + quantity
constexpr std::size_t single_write_min_size = 3;       // fc + address
constexpr std::size_t rw_write_address_offset = 5;
constexpr std::size_t rw_write_quantity_offset = 7;
constexpr std::size_t rw_min_size = 9;  // fc + read address, quantity + write address, quantity

}  // namespace

RequestScope request_scope(protocol::ByteView pdu) noexcept {
    RequestScope scope;
    if (pdu.empty()) return scope;
    scope.function = pdu[0];
    namespace fc = protocol::fc;
    switch (scope.function) {
        case fc::read_coils:
        case fc::read_discrete_inputs:
        case fc::read_holding_registers:
        case fc::read_input_registers:
        case fc::write_multiple_coils:
        case fc::write_multiple_registers:
            if (pdu.size() >= address_and_quantity_size) {
                scope.first = span(protocol::get_u16_be(pdu, address_offset), protocol::get_u16_be(pdu, quantity_offset));
            }
            break;
        case fc::write_single_coil:
        case fc::write_single_register:
            if (pdu.size() >= single_write_min_size) scope.first = span(protocol::get_u16_be(pdu, address_offset), 1);
            break;
        case fc::read_write_multiple_registers:
            if (pdu.size() >= rw_min_size) {
                scope.first = span(protocol::get_u16_be(pdu, address_offset), protocol::get_u16_be(pdu, quantity_offset));
                scope.second = span(protocol::get_u16_be(pdu, rw_write_address_offset),
                                    protocol::get_u16_be(pdu, rw_write_quantity_offset));
            }
            break;
        default:
            break;  // FC07, diagnostics, vendor codes: no register range
    }
    return scope;
}

bool request_allowed(const config::ModbusTcpConfig& config, const config::IpAddress& client, std::uint8_t unit,
                     const RequestScope& scope) noexcept {
    if (config.rules.empty()) return true;
    const auto allowed = [&](std::optional<config::RegisterRange> range) {
        return config.decide(client, unit, scope.function, range) == config::RuleAction::allow;
    };
    return allowed(scope.first) && (!scope.second || allowed(scope.second));
}

}  // namespace fieldbridge::northbound::modbus_tcp
