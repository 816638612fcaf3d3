#pragma once
/// @file decode_result.hpp
/// The three-way outcome of every decoder and framer: need more bytes, a complete
/// frame (with how many bytes it used), or malformed (with why, and how many bytes
/// to drop before trying again).

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace fieldbridge::protocol {

enum class DecodeStatus : std::uint8_t { need_more, complete, malformed };

/// Why a frame was rejected. Line workers count these per line and per device.
enum class DecodeError : std::uint8_t {
    none,
    bad_crc,          ///< CRC-16 does not verify
    wrong_address,    ///< frame from (or to) another slave than expected
    wrong_function,   ///< reply function code does not match the request
    bad_length,       ///< length field or frame length impossible for the function
    oversize,         ///< longer than the protocol allows
    bad_protocol_id,  ///< MBAP protocol identifier is not 0
    bad_hex,          ///< WTEC ASCII: a field that must be hex digits is not
    bad_framing,      ///< WTEC ASCII: missing '>' or CR LF
    bad_value,        ///< a field value outside what the protocol defines
    unexpected_reply  ///< a well-formed frame that does not answer the request
};

[[nodiscard]] std::string_view to_string(DecodeError error) noexcept;

template <typename T>
struct DecodeResult {
    DecodeStatus status = DecodeStatus::need_more;
    T value{};                         ///< valid when status == complete
    std::size_t consumed = 0;          ///< complete: bytes of the frame; malformed: bytes to drop
    DecodeError error = DecodeError::none;

    [[nodiscard]] bool complete() const noexcept { return status == DecodeStatus::complete; }
    [[nodiscard]] bool need_more() const noexcept { return status == DecodeStatus::need_more; }
    [[nodiscard]] bool malformed() const noexcept { return status == DecodeStatus::malformed; }

    static DecodeResult more() { return {}; }
    static DecodeResult ok(T v, std::size_t used) {
        return {DecodeStatus::complete, std::move(v), used, DecodeError::none};
    }
    static DecodeResult bad(DecodeError why, std::size_t drop) {
        return {DecodeStatus::malformed, T{}, drop, why};
    }
};

}  // namespace fieldbridge::protocol
