#include "models/modbus_request.hpp"

#include "protocol/rtu_frame.hpp"

namespace fieldbridge::sim {

std::optional<AddressedPdu> accept_rtu(protocol::ByteView frame, std::uint8_t address,
                                       std::optional<std::uint8_t> broadcast) {
    const auto decoded = protocol::decode_rtu(frame);
    if (!decoded.complete() || decoded.value.pdu.empty()) return std::nullopt;
    const bool to_all = broadcast.has_value() && decoded.value.address == *broadcast;
    if (!to_all && decoded.value.address != address) return std::nullopt;
    return AddressedPdu{decoded.value.pdu, to_all};
}

std::optional<protocol::Bytes> rtu_reply(const AddressedPdu& request, std::uint8_t address,
                                         const protocol::Response& response) {
    if (request.broadcast) return std::nullopt;
    const protocol::Bytes pdu = protocol::encode_response(response);
    return protocol::encode_rtu(address, pdu);
}

protocol::Response exception_of(std::uint8_t function, protocol::ExceptionCode code) {
    return protocol::ExceptionResponse{function, code};
}

std::variant<protocol::Request, protocol::Response> decode_or_exception(protocol::ByteView pdu) {
    auto decoded = protocol::decode_request(pdu);
    if (decoded.complete()) return std::move(decoded.value);
    return exception_of(pdu.empty() ? std::uint8_t{0} : pdu[0],
                        protocol::ExceptionCode::illegal_data_value);
}

WordPair split_u32(std::uint32_t value, bool high_word_first) noexcept {
    const auto high = static_cast<std::uint16_t>(value >> 16);
    const auto low = static_cast<std::uint16_t>(value & 0xFFFFu);
    return high_word_first ? WordPair{high, low} : WordPair{low, high};
}

std::uint32_t join_u32(std::uint16_t first, std::uint16_t second, bool high_word_first) noexcept {
    const std::uint16_t high = high_word_first ? first : second;
    const std::uint16_t low = high_word_first ? second : first;
    return (static_cast<std::uint32_t>(high) << 16) | low;
}

}  // namespace fieldbridge::sim
