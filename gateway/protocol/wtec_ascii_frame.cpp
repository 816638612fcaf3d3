#include "protocol/wtec_ascii_frame.hpp"

#include <stdexcept>
#include <utility>

#include "core/error.hpp"
#include "protocol/crc16.hpp"

namespace fieldbridge::protocol::wtec {

namespace {

constexpr char frame_start = '>';
constexpr char cr = '\r';
constexpr char lf = '\n';
constexpr std::size_t address_digits = 2;
constexpr std::size_t crc_digits = 4;
/// '>' + address + command + CRC: the shortest body (no data, no CR LF).
constexpr std::size_t min_body_size = 1 + address_digits + 1 + crc_digits;
constexpr std::size_t max_body_size = max_frame_size - 2;

[[nodiscard]] ByteView as_bytes(std::string_view text) noexcept {
    // char and unsigned char may alias each other; the CRC runs over the ASCII bytes.
    return {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()};
}

[[nodiscard]] std::string_view as_text(ByteView bytes) noexcept {
    return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}

/// Value of one upper-case hex digit, or -1.
[[nodiscard]] int hex_value(char c) noexcept {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

void check_encodable(const AsciiFrame& frame) {
    if (!is_command_char(frame.command)) {
        throw core::InvalidArgument("WTEC ASCII encode: command byte " +
                                    std::to_string(static_cast<unsigned char>(frame.command)) +
                                    " is not a letter or '$'");
    }
    if (frame.data.size() > max_data_size) {
        throw core::InvalidArgument(std::string("WTEC ASCII encode: command '") + frame.command +
                                    "' data has " + std::to_string(frame.data.size()) +
                                    " characters, more than the " +
                                    std::to_string(max_data_size) + " a frame can carry");
    }
    for (const char c : frame.data) {
        if (!is_data_char(c)) {
            throw core::InvalidArgument(std::string("WTEC ASCII encode: command '") +
                                        frame.command + "' data holds byte " +
                                        std::to_string(static_cast<unsigned char>(c)) +
                                        ", which is not printable ASCII or is '>'");
        }
    }
}

}  // namespace

bool is_command_char(char c) noexcept {
    // seed 003 section 1.2 lists the command as 'A'-'Z', 'a'-'z'; the command list
    // adds '$' (read all station numbers).
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '$';
}

bool is_data_char(char c) noexcept {
    // The `A` reply "Cstep [A]1.62" (seed 003, command 1) shows that data is free
    // printable text, not only the letters and digits section 1.2 lists.
    return c >= 0x20 && c <= 0x7E && c != frame_start;
}

std::optional<std::uint32_t> parse_hex(std::string_view digits) noexcept {
    if (digits.empty() || digits.size() > 8) return std::nullopt;
    std::uint32_t value = 0;
    for (const char c : digits) {
        const int digit = hex_value(c);
        if (digit < 0) return std::nullopt;
        value = (value << 4) | static_cast<std::uint32_t>(digit);
    }
    return value;
}

void append_hex(std::string& out, std::uint32_t value, std::size_t width) {
    static constexpr char digits[] = "0123456789ABCDEF";
    for (std::size_t i = width; i > 0; --i) {
        const std::size_t shift = (i - 1) * 4;
        out.push_back(shift < 32 ? digits[(value >> shift) & 0xFU] : '0');
    }
}

std::string encode_frame_body(const AsciiFrame& frame) {
    check_encodable(frame);
    std::string body;
    body.reserve(max_frame_size);
    body.push_back(frame_start);
    append_hex(body, frame.address, address_digits);
    body.push_back(frame.command);
    body += frame.data;
    // seed 003 section 1.2 / 3.2.2: CRC over '>' through the data, written high byte
    // first ("校验和 (H)" then "(L)") as four hex digits.
    append_hex(body, crc16_modbus(as_bytes(body)), crc_digits);
    return body;
}

std::string encode_frame(const AsciiFrame& frame) {
    std::string text = encode_frame_body(frame);
    text.push_back(cr);
    text.push_back(lf);
    return text;
}

DecodeResult<AsciiFrame> decode_frame_body(std::string_view body) {
    using Result = DecodeResult<AsciiFrame>;
    const std::size_t size = body.size();
    if (size == 0 || body.front() != frame_start) return Result::bad(DecodeError::bad_framing, size);
    if (size < min_body_size) return Result::bad(DecodeError::bad_length, size);
    if (size > max_body_size) return Result::bad(DecodeError::oversize, size);
    // Structure before fields: a CR, LF, control byte or second '>' anywhere means
    // this is not one frame body, whatever the digits around it say.
    for (const char c : body.substr(1)) {
        if (!is_data_char(c)) return Result::bad(DecodeError::bad_framing, size);
    }

    const auto address = parse_hex(body.substr(1, address_digits));
    if (!address) return Result::bad(DecodeError::bad_hex, size);
    const char command = body[1 + address_digits];
    if (!is_command_char(command)) return Result::bad(DecodeError::bad_framing, size);
    const std::size_t data_begin = 1 + address_digits + 1;
    const std::size_t crc_begin = size - crc_digits;
    const std::string_view data = body.substr(data_begin, crc_begin - data_begin);
    const auto crc = parse_hex(body.substr(crc_begin));
    if (!crc) return Result::bad(DecodeError::bad_hex, size);
    if (*crc != crc16_modbus(as_bytes(body.substr(0, crc_begin)))) {
        return Result::bad(DecodeError::bad_crc, size);
    }
    return Result::ok(AsciiFrame{static_cast<std::uint8_t>(*address), command, std::string(data)},
                      size);
}

DecodeResult<AsciiFrame> scan_frame(ByteView rx) {
    using Result = DecodeResult<AsciiFrame>;
    const std::string_view text = as_text(rx);
    const std::size_t start = text.find(frame_start);
    if (start == std::string_view::npos) {
        // Nothing can start a frame: an empty buffer waits, anything else is noise.
        return text.empty() ? Result::more() : Result::bad(DecodeError::bad_framing, text.size());
    }
    // seed 003 section 1.1: a frame ends with CR LF and is at most max_frame_size
    // characters including '>' and CR LF (64 here, see the header).
    // The CR can be no later than character max_frame_size - 1 (index limit - 2), so
    // anything else there already makes the frame too long: no need to wait for more.
    const std::size_t limit = start + max_frame_size;
    for (std::size_t i = start + 1; i < text.size(); ++i) {
        const char c = text[i];
        if (c == frame_start) {
            // The frame in progress lost its end; resynchronise on the new '>'.
            return Result::bad(DecodeError::bad_framing, i);
        }
        if (c == cr) {
            if (i + 1 >= text.size()) return Result::more();
            if (text[i + 1] != lf) return Result::bad(DecodeError::bad_framing, i + 1);
            const std::size_t end = i + 2;
            auto body = decode_frame_body(text.substr(start, i - start));
            if (!body.complete()) return Result::bad(body.error, end);
            return Result::ok(std::move(body.value), end);
        }
        if (c == lf || !is_data_char(c)) return Result::bad(DecodeError::bad_framing, i + 1);
        if (i + 2 >= limit) return Result::bad(DecodeError::oversize, i + 1);
    }
    return Result::more();
}

}  // namespace fieldbridge::protocol::wtec
