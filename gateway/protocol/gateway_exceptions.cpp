#include "protocol/gateway_exceptions.hpp"

namespace fieldbridge::protocol {

ExceptionCode exception_code(GatewayRefusal refusal) noexcept {
    // Modbus Application Protocol V1.1b3 section 7 for the meaning of each code.
    switch (refusal) {
        case GatewayRefusal::not_a_function:
        case GatewayRefusal::unsupported:
        case GatewayRefusal::denied: return ExceptionCode::illegal_function;
        case GatewayRefusal::bad_address: return ExceptionCode::illegal_data_address;
        case GatewayRefusal::bad_value: return ExceptionCode::illegal_data_value;
        case GatewayRefusal::path_down:
        // Withdrawn by the gateway (docs/modbus-tcp.md, "Cancelled requests"): the path
        // went away, not the device; 0x0B would tell the client the device is absent.
        case GatewayRefusal::cancelled: return ExceptionCode::gateway_path_unavailable;
        case GatewayRefusal::busy: return ExceptionCode::server_device_busy;
        case GatewayRefusal::no_answer:
        case GatewayRefusal::expired: return ExceptionCode::gateway_target_failed;
        case GatewayRefusal::gateway_failure: break;
    }
    return ExceptionCode::server_device_failure;
}

Bytes exception_pdu(core::FunctionCode function, ExceptionCode code) {
    // Section 7: the function byte with its high bit set, then the code.
    return {static_cast<std::uint8_t>(function.value | fc::exception_flag), static_cast<std::uint8_t>(code)};
}

Bytes exception_pdu(core::FunctionCode function, GatewayRefusal refusal) {
    return exception_pdu(function, exception_code(refusal));
}

ExceptionResponse exception_response(core::FunctionCode function, GatewayRefusal refusal) noexcept {
    return exception_response(function, exception_code(refusal));
}

ExceptionResponse exception_response(core::FunctionCode function, ExceptionCode code) noexcept {
    return ExceptionResponse{function.value, code};
}

}  // namespace fieldbridge::protocol
