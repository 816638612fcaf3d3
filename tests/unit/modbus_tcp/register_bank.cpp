#include "register_bank.hpp"

#include <type_traits>
#include <variant>

#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::northbound::modbus_tcp::test {

std::uint16_t RegisterBank::read(std::uint16_t address) const {
    const auto it = registers_.find(address);
    return it == registers_.end() ? address : it->second;
}

protocol::Bytes RegisterBank::answer(protocol::ByteView request_pdu) {
    using namespace protocol;
    const auto decoded = decode_request(request_pdu);
    const std::uint8_t function = request_pdu.empty() ? 0 : request_pdu[0];
    if (!decoded.complete()) {
        if (function == 0 || function >= 0x80) return Bytes{static_cast<std::uint8_t>(function | 0x80), 0x01};
        return encode_exception(function, ExceptionCode::illegal_data_value);
    }
    const auto read_values = [this](std::uint16_t address, std::uint16_t count) {
        std::vector<std::uint16_t> values;
        for (std::uint16_t i = 0; i < count; ++i) values.push_back(read(static_cast<std::uint16_t>(address + i)));
        return values;
    };
    return std::visit(
        [&](const auto& request) -> Bytes {
            using T = std::decay_t<decltype(request)>;
            if constexpr (std::is_same_v<T, ReadRegistersRequest>) {
                return encode_response(ReadRegistersResponse{request.function, read_values(request.address, request.count)});
            } else if constexpr (std::is_same_v<T, WriteSingleRegisterRequest>) {
                registers_[request.address] = request.value;
                return encode_response(WriteSingleResponse{fc::write_single_register, request.address, request.value});
            } else if constexpr (std::is_same_v<T, WriteMultipleRegistersRequest>) {
                for (std::size_t i = 0; i < request.values.size(); ++i) {
                    registers_[static_cast<std::uint16_t>(request.address + i)] = request.values[i];
                }
                return encode_response(WriteMultipleResponse{fc::write_multiple_registers, request.address,
                                                             static_cast<std::uint16_t>(request.values.size())});
            } else if constexpr (std::is_same_v<T, ReadWriteRegistersRequest>) {
                for (std::size_t i = 0; i < request.values.size(); ++i) {
                    registers_[static_cast<std::uint16_t>(request.write_address + i)] = request.values[i];
                }
                return encode_response(ReadRegistersResponse{fc::read_write_multiple_registers,
                                                             read_values(request.read_address, request.read_count)});
            } else {
                return encode_exception(function, ExceptionCode::illegal_function);
            }
        },
        decoded.value);
}

}  // namespace fieldbridge::northbound::modbus_tcp::test
