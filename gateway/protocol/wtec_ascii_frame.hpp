#pragma once
/// @file wtec_ascii_frame.hpp
/// WTEC-485 vendor ASCII frame (seed 003, section 1.2):
///   '>' + address (2 hex digits) + command letter + data + CRC (4 hex, high first) + CR LF
/// The CRC is CRC-16/MODBUS over the ASCII bytes from '>' through the data.
/// The manual gives 50 characters as the maximum frame length, but its own `B`/`b`
/// frames are 55: the limit here is 64 (docs/protocols.md).

#include <cstdint>
#include <string>
#include <string_view>

#include "protocol/bytes.hpp"
#include "protocol/decode_result.hpp"

namespace fieldbridge::protocol::wtec {

inline constexpr std::size_t max_frame_size = 64;
inline constexpr std::uint8_t broadcast_address = 0x00;
inline constexpr std::uint8_t max_address = 0xFD;  // 253

struct AsciiFrame {
    std::uint8_t address = 0;
    char command = 0;
    std::string data;  ///< the characters between the command letter and the CRC
    bool operator==(const AsciiFrame&) const = default;
};

/// The full frame text including '>' and the trailing CR LF.
[[nodiscard]] std::string encode_frame(const AsciiFrame& frame);

/// The frame text without CR LF ('>' ... CRC), as the manual prints examples.
[[nodiscard]] std::string encode_frame_body(const AsciiFrame& frame);

/// Scans a receive buffer for one frame: bytes before '>' are skipped (counted in
/// `consumed`); need_more until CR LF; malformed for bad CRC, non-hex address or
/// CRC digits, a command byte that is not a letter or '$', or no CR LF within
/// max_frame_size (drop `consumed` bytes and scan again).
[[nodiscard]] DecodeResult<AsciiFrame> scan_frame(ByteView rx);

/// Decodes an exact frame body as printed in the manual ('>' ... CRC, no CR LF).
[[nodiscard]] DecodeResult<AsciiFrame> decode_frame_body(std::string_view body);

}  // namespace fieldbridge::protocol::wtec
