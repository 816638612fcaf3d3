// The one mapping from the gateway's reasons to Modbus exception codes and the one
// encoder of exception PDUs (protocol/gateway_exceptions.hpp; the table in
// docs/modbus-tcp.md, "Exception contract").
#include <doctest/doctest.h>

#include "protocol/gateway_exceptions.hpp"

namespace p = fieldbridge::protocol;
using p::Bytes;
using p::ExceptionCode;
using p::GatewayRefusal;

TEST_CASE("gateway exceptions: every refusal has the code of the documented table") {
    const std::pair<GatewayRefusal, ExceptionCode> table[] = {
        {GatewayRefusal::not_a_function, ExceptionCode::illegal_function},
        {GatewayRefusal::unsupported, ExceptionCode::illegal_function},
        {GatewayRefusal::denied, ExceptionCode::illegal_function},
        {GatewayRefusal::bad_address, ExceptionCode::illegal_data_address},
        {GatewayRefusal::bad_value, ExceptionCode::illegal_data_value},
        {GatewayRefusal::path_down, ExceptionCode::gateway_path_unavailable},
        // Withdrawn by the gateway (shut down, reconfigured): the same code from a
        // serial device, a broadcast unit and an upstream unit.
        {GatewayRefusal::cancelled, ExceptionCode::gateway_path_unavailable},
        {GatewayRefusal::busy, ExceptionCode::server_device_busy},
        {GatewayRefusal::no_answer, ExceptionCode::gateway_target_failed},
        {GatewayRefusal::expired, ExceptionCode::gateway_target_failed},
        {GatewayRefusal::gateway_failure, ExceptionCode::server_device_failure},
    };
    for (const auto& [refusal, code] : table) {
        CAPTURE(static_cast<int>(refusal));
        CHECK(p::exception_code(refusal) == code);
        CHECK(p::exception_pdu(0x10, refusal) == Bytes{0x90, static_cast<std::uint8_t>(code)});
        CHECK(p::exception_response(0x10, refusal) == p::ExceptionResponse{0x10, code});
    }
}

TEST_CASE("gateway exceptions: the response form encodes to the same bytes as the PDU form") {
    const p::ExceptionResponse cancelled = p::exception_response(0x03, GatewayRefusal::cancelled);
    CHECK(p::encode_response(p::Response{cancelled}) == p::exception_pdu(0x03, GatewayRefusal::cancelled));
    CHECK(p::encode_exception(0x06, ExceptionCode::illegal_data_value) ==
          p::exception_pdu(0x06, ExceptionCode::illegal_data_value));
    // Any function byte is answered by setting bit 7 (a request with byte 0 gets 0x80).
    CHECK(p::exception_pdu(0x00, GatewayRefusal::not_a_function) == Bytes{0x80, 0x01});
    CHECK(p::exception_pdu(0x85, GatewayRefusal::not_a_function) == Bytes{0x85, 0x01});
}
