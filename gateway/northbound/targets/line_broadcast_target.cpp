#include "northbound/targets/line_broadcast_target.hpp"

#include <asio/post.hpp>

#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::northbound {

namespace {

/// What a device would have answered to the write (Modbus 6.5, 6.6, 6.11, 6.12).
std::optional<protocol::Response> write_echo(const protocol::Request& request) {
    using namespace protocol;
    if (const auto* coil = std::get_if<WriteSingleCoilRequest>(&request)) {
        return WriteSingleResponse{fc::write_single_coil, coil->address,
                                   static_cast<std::uint16_t>(coil->value ? 0xFF00 : 0x0000)};
    }
    if (const auto* reg = std::get_if<WriteSingleRegisterRequest>(&request)) {
        return WriteSingleResponse{fc::write_single_register, reg->address, reg->value};
    }
    if (const auto* coils = std::get_if<WriteMultipleCoilsRequest>(&request)) {
        return WriteMultipleResponse{fc::write_multiple_coils, coils->address,
                                     static_cast<std::uint16_t>(coils->values.size())};
    }
    if (const auto* regs = std::get_if<WriteMultipleRegistersRequest>(&request)) {
        return WriteMultipleResponse{fc::write_multiple_registers, regs->address,
                                     static_cast<std::uint16_t>(regs->values.size())};
    }
    return std::nullopt;
}

}  // namespace

LineBroadcastTarget::LineBroadcastTarget(asio::io_context& io, engine::LineWorker& line,
                                         std::vector<std::uint8_t> addresses, engine::Duration command_ttl)
    : io_(io), line_(line), addresses_(std::move(addresses)), command_ttl_(command_ttl) {}

void LineBroadcastTarget::handle(std::uint8_t /*unit*/, protocol::ByteView request_pdu, const ClientRef& /*client*/,
                                 PduHandler done) {
    protocol::Bytes answer;
    const auto decoded = protocol::decode_request(request_pdu);
    const std::uint8_t function = request_pdu.empty() ? 0 : request_pdu[0];
    const std::uint8_t usable = (function == 0 || function >= 0x80) ? std::uint8_t{0x7F} : function;
    if (!decoded.complete()) {
        answer = protocol::encode_exception(usable, protocol::ExceptionCode::illegal_data_value);
    } else if (const auto echo = write_echo(decoded.value); !echo) {
        answer = protocol::encode_exception(usable, protocol::ExceptionCode::illegal_function);
    } else if (!line_.line_up()) {
        answer = protocol::encode_exception(usable, protocol::ExceptionCode::gateway_path_unavailable);
    } else {
        const auto now = engine::Clock::now();
        for (const std::uint8_t address : addresses_) {
            engine::Transaction transaction;
            transaction.device = engine::broadcast_device;
            transaction.address = address;
            transaction.payload = engine::ModbusPayload{decoded.value};
            transaction.priority = engine::Priority::command;
            transaction.deadline = now + command_ttl_;
            transaction.on_done = [](const engine::Outcome&) {};
            line_.submit(std::move(transaction));
        }
        answer = protocol::encode_response(*echo);
    }
    asio::post(io_, [done = std::move(done), answer = std::move(answer)]() mutable { done(std::move(answer)); });
}

}  // namespace fieldbridge::northbound
