#pragma once
/// @file gateway_exceptions.hpp
/// The one place where the gateway decides which Modbus exception a northbound
/// client gets when the answer does not come from a device (spec §4, §8;
/// docs/modbus-tcp.md, "Exception responses"), and the one encoder of exception
/// PDUs for every target (serial device, broadcast unit, upstream unit) and for the
/// server itself. Pure.
#include <cstdint>

#include "core/modbus_ids.hpp"
#include "protocol/bytes.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::protocol {

/// Why a request is answered by the gateway instead of by its device.
enum class GatewayRefusal : std::uint8_t {
    not_a_function,   ///< function byte 0 or >= 0x80: no Modbus function code at all
    unsupported,      ///< a function code the target does not carry
    denied,           ///< an access rule or a protected register without allow_protected
    bad_address,      ///< outside the map, across a hole, half of a 32-bit pair
    bad_value,        ///< quantity, byte count, length or value out of range
    path_down,        ///< no route, line or link down
    cancelled,        ///< withdrawn by the gateway (shut down, reconfigured) before its answer came
    busy,             ///< a queue is full, or the line's broadcast budget is spent
    no_answer,        ///< the device did not answer (timeout, offline)
    expired,          ///< its deadline passed before it could start: never sent
    gateway_failure,  ///< the gateway could not carry it (internal error)
};

/// The one mapping (the table in docs/modbus-tcp.md, "Exception contract"):
/// 0x01 not_a_function / unsupported / denied, 0x02 bad_address, 0x03 bad_value,
/// 0x0A path_down / cancelled, 0x06 busy, 0x0B no_answer / expired, 0x04 gateway_failure.
[[nodiscard]] ExceptionCode exception_code(GatewayRefusal refusal) noexcept;

/// Why a request PDU that does not decode is refused: not_a_function for a function
/// byte 0 or >= 0x80 (or an empty PDU), bad_value for any other (a quantity, byte count
/// or length its function cannot carry: Modbus 6.x, 0x03).
[[nodiscard]] constexpr GatewayRefusal refusal_for_undecodable(core::FunctionCode function) noexcept {
    return core::is_function_code(function) ? GatewayRefusal::bad_value : GatewayRefusal::not_a_function;
}

/// The exception PDU to a request whose function code is @p function as it came
/// (pdu_function(): FunctionCode{0} for an empty PDU): that byte with bit 7 set, then
/// the code. The same rule for every byte, so a request with function byte 0 gets 0x80
/// and one with 0x80..0xFF gets its own byte back (encode_exception() takes real
/// function codes only). The only place that lays out exception bytes
/// (encode_exception() and encode_response() of an ExceptionResponse use it too).
[[nodiscard]] Bytes exception_pdu(core::FunctionCode function, ExceptionCode code);
[[nodiscard]] Bytes exception_pdu(core::FunctionCode function, GatewayRefusal refusal);

/// The same answers as a decoded Response (what the device agents and the MQTT
/// sources hand back), encoded later by encode_response() into exception_pdu() bytes.
[[nodiscard]] ExceptionResponse exception_response(core::FunctionCode function, GatewayRefusal refusal) noexcept;
/// A code a profile decided (validate(), a device's "not executed"): only the form.
[[nodiscard]] ExceptionResponse exception_response(core::FunctionCode function, ExceptionCode code) noexcept;

}  // namespace fieldbridge::protocol
