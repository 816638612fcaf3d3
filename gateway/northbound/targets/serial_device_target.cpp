#include "northbound/targets/serial_device_target.hpp"

#include <asio/post.hpp>

#include "protocol/gateway_exceptions.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::northbound {

SerialDeviceTarget::SerialDeviceTarget(asio::io_context& io, engine::DeviceAgent& agent,
                                       const engine::LineWorker& line)
    : io_(io), agent_(agent), line_(line) {}

void SerialDeviceTarget::answer(PduHandler done, protocol::Bytes pdu) {
    // Never from inside handle() (unit_target.hpp).
    asio::post(io_, [done = std::move(done), pdu = std::move(pdu)]() mutable { done(std::move(pdu)); });
}

void SerialDeviceTarget::handle(core::UnitId /*unit*/, const RequestPdu& request, const ClientRef& /*client*/,
                                PduHandler done) {
    const auto& decoded = request.decoded;
    const core::FunctionCode function = request.function();
    if (!decoded.complete()) {
        answer(std::move(done), protocol::exception_pdu(function, protocol::refusal_for_undecodable(function)));
        return;
    }
    if (!line_.line_up()) {
        answer(std::move(done), protocol::exception_pdu(function, protocol::GatewayRefusal::path_down));
        return;
    }
    agent_.request(decoded.value, [done = std::move(done)](const protocol::Response& response) {
        done(protocol::encode_response(response));
    });
}

}  // namespace fieldbridge::northbound
