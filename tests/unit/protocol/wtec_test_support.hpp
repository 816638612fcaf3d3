#pragma once
/// @file wtec_test_support.hpp
/// Helpers shared by the WTEC ASCII codec tests: text as bytes, and a decode result
/// as a short string that CHECKs compare ("complete", "malformed bad_crc").
#include <cstdint>
#include <string>
#include <string_view>

#include "protocol/bytes.hpp"
#include "protocol/decode_result.hpp"

namespace wtec_test {

inline fieldbridge::protocol::ByteView bytes(std::string_view text) {
    return {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()};
}

template <typename T>
std::string describe(const fieldbridge::protocol::DecodeResult<T>& r) {
    using fieldbridge::protocol::DecodeStatus;
    switch (r.status) {
        case DecodeStatus::need_more: return "need_more";
        case DecodeStatus::complete: return "complete";
        case DecodeStatus::malformed: break;
    }
    return "malformed " + std::string(to_string(r.error));
}

inline std::string malformed(fieldbridge::protocol::DecodeError why) {
    return "malformed " + std::string(to_string(why));
}

}  // namespace wtec_test
