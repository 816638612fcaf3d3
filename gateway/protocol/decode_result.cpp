#include "protocol/decode_result.hpp"

namespace fieldbridge::protocol {

// The enumerator names: stable words for logs, counters and JSON results.
std::string_view to_string(DecodeError error) noexcept {
    switch (error) {
        case DecodeError::none: return "none";
        case DecodeError::bad_crc: return "bad_crc";
        case DecodeError::wrong_address: return "wrong_address";
        case DecodeError::wrong_function: return "wrong_function";
        case DecodeError::bad_length: return "bad_length";
        case DecodeError::oversize: return "oversize";
        case DecodeError::bad_protocol_id: return "bad_protocol_id";
        case DecodeError::bad_hex: return "bad_hex";
        case DecodeError::bad_framing: return "bad_framing";
        case DecodeError::bad_value: return "bad_value";
        case DecodeError::unexpected_reply: return "unexpected_reply";
    }
    return "unknown";
}

}  // namespace fieldbridge::protocol
