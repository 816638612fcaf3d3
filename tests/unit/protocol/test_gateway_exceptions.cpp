// The one mapping from the gateway's reasons to Modbus exception codes and the one
// encoder of exception PDUs (protocol/gateway_exceptions.hpp; the table in
// docs/modbus-tcp.md, "Exception contract").
#include <doctest/doctest.h>

#include "protocol/gateway_exceptions.hpp"

namespace p = fieldbridge::protocol;
using fieldbridge::core::FunctionCode;
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
        CHECK(p::exception_pdu(FunctionCode{0x10}, refusal) == Bytes{0x90, static_cast<std::uint8_t>(code)});
        CHECK(p::exception_response(FunctionCode{0x10}, refusal) == p::ExceptionResponse{0x10, code});
    }
}

TEST_CASE("gateway exceptions: the response form encodes to the same bytes as the PDU form") {
    const p::ExceptionResponse cancelled = p::exception_response(FunctionCode{0x03}, GatewayRefusal::cancelled);
    CHECK(p::encode_response(p::Response{cancelled}) == p::exception_pdu(FunctionCode{0x03}, GatewayRefusal::cancelled));
    CHECK(p::encode_exception(0x06, ExceptionCode::illegal_data_value) ==
          p::exception_pdu(FunctionCode{0x06}, ExceptionCode::illegal_data_value));
    // Any function byte is answered by setting bit 7 (a request with byte 0 gets 0x80).
    CHECK(p::exception_pdu(FunctionCode{0x00}, GatewayRefusal::not_a_function) == Bytes{0x80, 0x01});
    CHECK(p::exception_pdu(FunctionCode{0x85}, GatewayRefusal::not_a_function) == Bytes{0x85, 0x01});
}

TEST_CASE("gateway exceptions: the function code comes back as it came, with bit 7 set") {
    // Unknown function codes (vendor, user-defined 0x41..0x48, 0x64..0x6E) and the
    // highest code are answered under their own byte.
    CHECK(p::exception_pdu(FunctionCode{0x41}, GatewayRefusal::unsupported) == Bytes{0xC1, 0x01});
    CHECK(p::exception_pdu(FunctionCode{0x7F}, GatewayRefusal::path_down) == Bytes{0xFF, 0x0A});
    // A byte with the high bit already set is no function code: it keeps its byte, 0x01.
    CHECK(p::exception_pdu(FunctionCode{0xFF}, GatewayRefusal::not_a_function) == Bytes{0xFF, 0x01});
    CHECK(p::exception_pdu(FunctionCode{0x80}, GatewayRefusal::not_a_function) == Bytes{0x80, 0x01});
    // The decoded form keeps the function code without the flag; encode_response()
    // refuses what is no function code rather than answer it twice flagged.
    CHECK(p::exception_response(FunctionCode{0x41}, GatewayRefusal::busy) ==
          p::ExceptionResponse{0x41, ExceptionCode::server_device_busy});
    CHECK(p::encode_response(p::Response{p::exception_response(FunctionCode{0x41}, GatewayRefusal::busy)}) ==
          Bytes{0xC1, 0x06});
    CHECK_THROWS(static_cast<void>(
        p::encode_response(p::Response{p::exception_response(FunctionCode{0x85}, GatewayRefusal::busy)})));
}

TEST_CASE("gateway exceptions: a request that does not decode is refused by its function byte") {
    for (const int byte : {0x00, 0x80, 0x83, 0xFF}) {
        CAPTURE(byte);
        CHECK(p::refusal_for_undecodable(FunctionCode{static_cast<std::uint8_t>(byte)}) ==
              GatewayRefusal::not_a_function);
    }
    for (const int byte : {0x01, 0x03, 0x10, 0x41, 0x7F}) {
        CAPTURE(byte);
        CHECK(p::refusal_for_undecodable(FunctionCode{static_cast<std::uint8_t>(byte)}) == GatewayRefusal::bad_value);
    }
    // An empty PDU has no function byte: pdu_function() reads it as 0.
    CHECK(p::pdu_function(p::ByteView{}) == FunctionCode{0x00});
    CHECK(p::pdu_function(Bytes{0x90, 0x02}) == FunctionCode{0x90});
}

TEST_CASE("gateway exceptions: typed function codes are the codec's bytes") {
    CHECK(p::fn::read_coils.value == p::fc::read_coils);
    CHECK(p::fn::read_write_multiple_registers.value == p::fc::read_write_multiple_registers);
    CHECK(p::function_code(p::Request{p::WriteSingleRegisterRequest{0x0010, 1}}) == p::fn::write_single_register);
    CHECK(p::function_code(p::Request{p::OpaqueRequest{0x41, {}}}) == FunctionCode{0x41});
    CHECK(p::function_code(p::ReadRegistersRequest{p::fc::read_input_registers, 0, 1}) ==
          p::fn::read_input_registers);
}
