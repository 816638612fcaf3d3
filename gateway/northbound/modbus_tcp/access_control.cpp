// Request scope for access rules. Field offsets: Modbus Application Protocol
// V1.1b3 section 6 (request PDUs of FC01-06, 0F, 10, 16, 17).
#include "northbound/modbus_tcp/access_control.hpp"

#include <algorithm>
#include <type_traits>
#include <variant>

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
constexpr std::uint8_t mask_write_register = 0x16;  // Modbus 6.16: fc + address + AND mask + OR mask

/// What a request whose registers cannot be known touches, as far as the rules are
/// concerned: everything (rules fail closed, docs/modbus-tcp.md).
constexpr config::RegisterRange every_register{0x0000, 0xFFFF};

/// Function codes that read no register and change nothing (Modbus 6.7, 6.9, 6.10,
/// 6.13: read exception status, get comm event counter / log, report server ID).
[[nodiscard]] bool touches_no_register(core::FunctionCode function) noexcept {
    return function == protocol::fn::read_exception_status || function == core::FunctionCode{0x0B} ||
           function == core::FunctionCode{0x0C} || function == core::FunctionCode{0x11};
}

}  // namespace

RequestScope request_scope(protocol::ByteView pdu) noexcept {
    RequestScope scope;
    if (pdu.empty()) {
        scope.first = every_register;
        return scope;
    }
    scope.function = protocol::pdu_function(pdu);
    // The byte selects the layout of the fields to read: the codec's constants.
    namespace fc = protocol::fc;
    switch (scope.function.value) {
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
        case mask_write_register:
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
            if (touches_no_register(scope.function)) return scope;
            break;  // FC08, 14, 15, 18, 2B, vendor codes: what they touch is not known
    }
    // A PDU too short for its address fields, or a function code whose registers
    // the server does not derive: it may touch any register.
    if (!scope.first) scope.first = every_register;
    return scope;
}

RequestScope request_scope(const RequestPdu& request) noexcept {
    if (!request.decoded.complete()) return request_scope(request.bytes);
    RequestScope scope;
    scope.function = request.function();
    std::visit(
        [&](const auto& r) {
            using R = std::decay_t<decltype(r)>;
            if constexpr (std::is_same_v<R, protocol::ReadBitsRequest> || std::is_same_v<R, protocol::ReadRegistersRequest>) {
                scope.first = span(r.address, r.count);
            } else if constexpr (std::is_same_v<R, protocol::WriteSingleCoilRequest> ||
                                 std::is_same_v<R, protocol::WriteSingleRegisterRequest> ||
                                 std::is_same_v<R, protocol::MaskWriteRegisterRequest>) {
                scope.first = span(r.address, 1);
            } else if constexpr (std::is_same_v<R, protocol::WriteMultipleCoilsRequest> ||
                                 std::is_same_v<R, protocol::WriteMultipleRegistersRequest>) {
                scope.first = span(r.address, static_cast<std::uint16_t>(r.values.size()));
            } else if constexpr (std::is_same_v<R, protocol::ReadWriteRegistersRequest>) {
                scope.first = span(r.read_address, r.read_count);
                scope.second = span(r.write_address, static_cast<std::uint16_t>(r.values.size()));
            } else if constexpr (std::is_same_v<R, protocol::ReadExceptionStatusRequest>) {
                // reads no register
            } else {
                // Opaque: FC0B, 0C, 11 touch nothing; anything else may touch everything.
                if (!touches_no_register(scope.function)) scope.first = every_register;
            }
        },
        request.decoded.value);
    return scope;
}

bool request_allowed(const config::ModbusTcpConfig& config, const config::IpAddress& client, core::UnitId unit,
                     const RequestScope& scope) noexcept {
    if (config.rules.empty()) return true;
    const auto allowed = [&](std::optional<config::RegisterRange> range) {
        return config.decide(client, unit, scope.function, range) == config::RuleAction::allow;
    };
    return allowed(scope.first) && (!scope.second || allowed(scope.second));
}

}  // namespace fieldbridge::northbound::modbus_tcp
