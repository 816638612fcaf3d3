// The Modbus PDU codec (protocol/modbus_pdu.hpp): decode_request as the Modbus TCP
// server meets a client's PDU, decode_response as a reply to the request it answers,
// and the length predictors the framers rely on.
// Input: one byte L, the request PDU (L bytes), then the response PDU.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <variant>

#include "fuzz_input.hpp"
#include "protocol/modbus_pdu.hpp"

namespace {

namespace protocol = fieldbridge::protocol;

/// A predicted length must agree with what the exact-length decoder accepted.
void check_prediction(const std::optional<protocol::PredictedLength>& predicted, std::size_t size) {
    if (!predicted) return;
    FB_FUZZ_CHECK(predicted->status == protocol::DecodeStatus::complete && predicted->length == size);
}

/// The bits of a request's last byte that carry values: all but an FC0F's padding.
std::uint8_t padding_mask(const protocol::Request& request) {
    const auto* coils = std::get_if<protocol::WriteMultipleCoilsRequest>(&request);
    if (coils == nullptr || coils->values.size() % 8 == 0) return 0xFF;
    return static_cast<std::uint8_t>((1u << (coils->values.size() % 8)) - 1u);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    fieldbridge::fuzz::FuzzInput input(data, size);
    const auto request_pdu = input.take(input.byte());
    const auto response_pdu = input.rest();

    const auto request = protocol::decode_request(request_pdu);
    FB_FUZZ_CHECK(!request.need_more());  // exact-length decoder
    if (request.malformed()) {
        FB_FUZZ_CHECK(request.consumed == request_pdu.size() && request.error != protocol::DecodeError::none);
        return 0;
    }
    // The decoded request re-encodes to its bytes, except the padding bits of an FC0F's
    // last byte, which the decoder ignores and the encoder writes as 0.
    const auto request_again = protocol::encode_request(request.value);
    FB_FUZZ_CHECK(request_again.size() == request_pdu.size() && !request_again.empty());
    FB_FUZZ_CHECK(std::equal(request_again.begin(), request_again.end() - 1, request_pdu.begin()));
    FB_FUZZ_CHECK(request_again.back() == (request_pdu.back() & padding_mask(request.value)));
    FB_FUZZ_CHECK(protocol::function_of(request.value) == request_pdu[0]);
    check_prediction(protocol::predict_request_pdu_length(request_pdu), request_pdu.size());

    const auto response = protocol::decode_response(response_pdu, request.value);
    FB_FUZZ_CHECK(!response.need_more());
    if (response.malformed()) {
        FB_FUZZ_CHECK(response.consumed == response_pdu.size() && response.error != protocol::DecodeError::none);
        return 0;
    }
    const auto response_again = protocol::encode_response(response.value);
    FB_FUZZ_CHECK(response_again.size() == response_pdu.size() &&
          std::equal(response_again.begin(), response_again.end(), response_pdu.begin()));
    check_prediction(protocol::predict_response_pdu_length(response_pdu, request.value), response_pdu.size());
    return 0;
}
