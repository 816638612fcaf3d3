#include "northbound/targets/serial_device_target.hpp"

#include <asio/post.hpp>

#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::northbound {

namespace {

protocol::Bytes exception_pdu(protocol::ByteView request_pdu, protocol::ExceptionCode code) {
    const std::uint8_t function = request_pdu.empty() ? 0 : request_pdu[0];
    // encode_exception needs 1..127: a PDU without a usable function code is answered
    // as 0xFF (0x7F | 0x80), the highest code, rather than not at all.
    const std::uint8_t usable = (function == 0 || function >= 0x80) ? std::uint8_t{0x7F} : function;
    return protocol::encode_exception(usable, code);
}

}  // namespace

SerialDeviceTarget::SerialDeviceTarget(asio::io_context& io, engine::DeviceAgent& agent,
                                       const engine::LineWorker& line)
    : io_(io), agent_(agent), line_(line) {}

void SerialDeviceTarget::answer(PduHandler done, protocol::Bytes pdu) {
    // Never from inside handle() (unit_target.hpp).
    asio::post(io_, [done = std::move(done), pdu = std::move(pdu)]() mutable { done(std::move(pdu)); });
}

void SerialDeviceTarget::handle(std::uint8_t /*unit*/, protocol::ByteView request_pdu, const ClientRef& /*client*/,
                                PduHandler done) {
    const auto decoded = protocol::decode_request(request_pdu);
    if (!decoded.complete()) {
        // A function code 0 / >= 0x80 is no function at all; anything else that does
        // not decode has a bad quantity, byte count or length (Modbus 6.x: 0x03).
        const bool bad_function = request_pdu.empty() || request_pdu[0] == 0 || request_pdu[0] >= 0x80;
        answer(std::move(done), exception_pdu(request_pdu, bad_function ? protocol::ExceptionCode::illegal_function
                                                                         : protocol::ExceptionCode::illegal_data_value));
        return;
    }
    if (!line_.line_up()) {
        answer(std::move(done), exception_pdu(request_pdu, protocol::ExceptionCode::gateway_path_unavailable));
        return;
    }
    agent_.request(decoded.value, [done = std::move(done)](const protocol::Response& response) {
        done(protocol::encode_response(response));
    });
}

}  // namespace fieldbridge::northbound
