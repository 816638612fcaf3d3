#include "models/generic_modbus_model.hpp"

#include <stdexcept>
#include <string>

#include "models/modbus_request.hpp"
#include "protocol/rtu_frame.hpp"

namespace fieldbridge::sim {
namespace {

using protocol::ExceptionCode;
namespace fc = protocol::fc;

constexpr std::uint8_t generic_max_address = 247;  // Modbus over Serial Line 2.2
constexpr std::size_t generic_register_count = 0x10000;

bool generic_fits(std::uint16_t address, std::size_t count) noexcept { return std::size_t{address} + count <= generic_register_count; }

}  // namespace

GenericModbusModel::GenericModbusModel(std::uint8_t address) : address_(address), holding_(generic_register_count) {
    if (address < 1 || address > generic_max_address) {
        throw std::invalid_argument("modbus: address " + std::to_string(address) +
                                    " is outside 1-247 (0 is the broadcast address)");
    }
    for (std::size_t a = 0; a < generic_register_count; ++a) holding_[a] = static_cast<std::uint16_t>(a);
}

std::optional<protocol::Bytes> GenericModbusModel::on_frame(protocol::ByteView frame, Clock::time_point) {
    const auto request = accept_rtu(frame, address_, protocol::modbus_broadcast_address);
    if (!request) return std::nullopt;
    const std::uint8_t function = request->pdu[0];
    if (function != fc::read_holding_registers && function != fc::read_input_registers &&
        function != fc::write_single_register && function != fc::write_multiple_registers) {
        return rtu_reply(*request, address_, exception_of(function, ExceptionCode::illegal_function));
    }
    auto decoded = decode_or_exception(request->pdu);
    if (auto* error = std::get_if<protocol::Response>(&decoded)) return rtu_reply(*request, address_, *error);
    return rtu_reply(*request, address_, handle(std::get<protocol::Request>(decoded)));
}

protocol::Response GenericModbusModel::handle(const protocol::Request& request) {
    if (const auto* read = std::get_if<protocol::ReadRegistersRequest>(&request)) {
        if (!generic_fits(read->address, read->count)) return exception_of(read->function, ExceptionCode::illegal_data_address);
        protocol::ReadRegistersResponse response{read->function, {}};
        for (std::size_t a = read->address; a < std::size_t{read->address} + read->count; ++a) {
            response.values.push_back(read->function == fc::read_holding_registers ? holding_[a]
                                                                                   : static_cast<std::uint16_t>(a));
        }
        return response;
    }
    if (const auto* single = std::get_if<protocol::WriteSingleRegisterRequest>(&request)) {
        holding_[single->address] = single->value;
        return protocol::WriteSingleResponse{fc::write_single_register, single->address, single->value};
    }
    const auto& multiple = std::get<protocol::WriteMultipleRegistersRequest>(request);
    if (!generic_fits(multiple.address, multiple.values.size())) {
        return exception_of(fc::write_multiple_registers, ExceptionCode::illegal_data_address);
    }
    for (std::size_t i = 0; i < multiple.values.size(); ++i) holding_[multiple.address + i] = multiple.values[i];
    return protocol::WriteMultipleResponse{fc::write_multiple_registers, multiple.address,
                                           static_cast<std::uint16_t>(multiple.values.size())};
}

std::string GenericModbusModel::control(std::string_view command, Clock::time_point) {
    return "modbus: no control commands (\"" + std::string(command) + "\")";
}

std::unique_ptr<BusDevice> make_generic_modbus(std::uint8_t address) {
    return std::make_unique<GenericModbusModel>(address);
}

}  // namespace fieldbridge::sim
