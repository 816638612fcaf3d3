#pragma once
/// @file wtec_ascii_frame.hpp
/// WTEC-485 vendor ASCII frame (seed 003, section 1.2):
///   '>' + address (2 hex digits) + command letter + data + CRC (4 hex, high first) + CR LF
/// The CRC is CRC-16/MODBUS over the ASCII bytes from '>' through the data.
/// The manual gives 50 characters as the maximum frame length, but its own `B`/`b`
/// frames are 55: the limit here is 64 (docs/protocols.md).
///
/// Hex digits (address, CRC and the typed hex fields of wtec_ascii_commands.hpp) are
/// upper case only, on encode and on decode: every example of the manual is upper
/// case, the CRC covers the literal characters, and 'A' and 'a' differ in one bit
/// (0x20), so accepting both would hide a class of line errors. Lower case is bad_hex.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "protocol/bytes.hpp"
#include "protocol/decode_result.hpp"

namespace fieldbridge::protocol::wtec {

inline constexpr std::size_t max_frame_size = 64;
inline constexpr std::uint8_t broadcast_address = 0x00;
inline constexpr std::uint8_t max_address = 0xFD;  // 253
/// '>' + 2 address digits + command + 4 CRC digits + CR LF.
inline constexpr std::size_t frame_overhead = 10;
inline constexpr std::size_t max_data_size = max_frame_size - frame_overhead;

struct AsciiFrame {
    std::uint8_t address = 0;
    char command = 0;
    std::string data;  ///< the characters between the command letter and the CRC
    bool operator==(const AsciiFrame&) const = default;
};

/// True for a valid command byte: an ASCII letter or '$'.
[[nodiscard]] bool is_command_char(char c) noexcept;

/// True for a character allowed in the data field: printable ASCII (0x20-0x7E)
/// except '>', which only starts a frame (the `A` reply carries ' ', '[', ']', '.').
[[nodiscard]] bool is_data_char(char c) noexcept;

/// Parses 1 to 8 upper-case hex digits; nullopt for anything else.
[[nodiscard]] std::optional<std::uint32_t> parse_hex(std::string_view digits) noexcept;

/// Appends the low @p width hex digits of @p value, upper case, most significant first.
void append_hex(std::string& out, std::uint32_t value, std::size_t width);

/// The full frame text including '>' and the trailing CR LF.
/// Throws core::InvalidArgument when the frame cannot be sent as it is: a command
/// byte that is not a letter or '$', a data character that is not is_data_char, or
/// data longer than max_data_size.
[[nodiscard]] std::string encode_frame(const AsciiFrame& frame);

/// The frame text without CR LF ('>' ... CRC), as the manual prints examples.
/// Throws like encode_frame.
[[nodiscard]] std::string encode_frame_body(const AsciiFrame& frame);

/// Scans a receive buffer for one frame: bytes before '>' are skipped (counted in
/// `consumed`); need_more until CR LF; malformed for bad CRC, non-hex address or
/// CRC digits, a command byte that is not a letter or '$', or no CR LF within
/// max_frame_size (drop `consumed` bytes and scan again).
/// `consumed` always counts from the start of @p rx, skipped bytes included.
/// Malformed cases and what `consumed` drops:
///  - no '>' in the buffer: bad_framing, the whole buffer;
///  - a second '>' before CR LF (the first frame lost its end): bad_framing, up to
///    the second '>' so the next scan starts there;
///  - a bare CR, a bare LF or a non-printable byte inside the frame: bad_framing,
///    through that byte;
///  - no CR within the first max_frame_size - 1 characters from '>' (so CR LF cannot
///    end the frame within max_frame_size): oversize, those characters;
///  - a terminated frame whose content is wrong (too short, bad hex, bad command
///    byte, bad CRC): as decode_frame_body, the whole frame through LF.
/// Bytes before '>' followed by an unfinished frame: need_more, consumed 0 (the
/// caller keeps the whole buffer and scans again when more arrives).
[[nodiscard]] DecodeResult<AsciiFrame> scan_frame(ByteView rx);

/// Decodes an exact frame body as printed in the manual ('>' ... CRC, no CR LF).
/// Malformed: bad_framing (no leading '>', a bad command byte or data character),
/// bad_length (shorter than '>' + address + command + CRC), oversize, bad_hex
/// (address or CRC digits), bad_crc. `consumed` is body.size() in every case.
[[nodiscard]] DecodeResult<AsciiFrame> decode_frame_body(std::string_view body);

}  // namespace fieldbridge::protocol::wtec
