#pragma once
/// @file log_text.hpp
/// Text from outside made safe for a log line (docs/service.md, "Logs"). Every
/// message the daemon logs passes through escape_log_text() in the logger's formatter
/// (daemon/logging.cpp), so no call site can let a newline or an escape sequence from
/// an MQTT client, a Modbus TCP peer, an HTTP client or an upstream device forge a
/// line or drive the operator's terminal. quoted() is for call sites that put such a
/// string between quotes, so that a quote inside it cannot end the quotation.
///
/// The escape form: `\n`, `\r` and `\t` for those three; `\xHH` (two upper-case hex
/// digits) for every other byte that is a C0 control character or DEL, for each byte
/// of a C1 control character (U+0080..U+009F) and of the line and paragraph
/// separators U+2028 / U+2029 in UTF-8, and for every byte that is not part of valid
/// UTF-8. Everything else, valid UTF-8 included, is kept as it is.
#include <cstddef>
#include <string>
#include <string_view>

namespace fieldbridge::core {

namespace log_text_detail {

/// Length of the valid UTF-8 sequence starting at @p i (2..4), 0 when there is none
/// (overlong forms, surrogates and code points above U+10FFFF are not valid).
[[nodiscard]] constexpr std::size_t utf8_sequence(std::string_view text, std::size_t i, char32_t& code) noexcept {
    const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
    const unsigned char lead = byte(i);
    std::size_t length = 0;
    char32_t minimum = 0;
    if (lead >= 0xC2 && lead <= 0xDF) {
        length = 2;
        code = lead & 0x1Fu;
        minimum = 0x80;
    } else if (lead >= 0xE0 && lead <= 0xEF) {
        length = 3;
        code = lead & 0x0Fu;
        minimum = 0x800;
    } else if (lead >= 0xF0 && lead <= 0xF4) {
        length = 4;
        code = lead & 0x07u;
        minimum = 0x10000;
    } else {
        return 0;
    }
    if (text.size() - i < length) return 0;
    for (std::size_t k = 1; k < length; ++k) {
        if ((byte(i + k) & 0xC0u) != 0x80u) return 0;
        code = (code << 6) | (byte(i + k) & 0x3Fu);
    }
    if (code < minimum || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return 0;
    return length;
}

inline void append_hex(std::string& out, unsigned char byte) {
    constexpr std::string_view digits = "0123456789ABCDEF";
    out += "\\x";
    out += digits[byte >> 4];
    out += digits[byte & 0x0F];
}

}  // namespace log_text_detail

/// True when escape_log_text(@p text) differs from @p text.
[[nodiscard]] constexpr bool needs_log_escape(std::string_view text) noexcept {
    for (std::size_t i = 0; i < text.size();) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (c >= 0x20 && c < 0x7F) {
            ++i;
            continue;
        }
        if (c < 0x80) return true;
        char32_t code = 0;
        const std::size_t length = log_text_detail::utf8_sequence(text, i, code);
        if (length == 0 || code <= 0x9F || code == 0x2028 || code == 0x2029) return true;
        i += length;
    }
    return false;
}

/// @p text in the escape form above: one line of printable text whatever it held.
[[nodiscard]] inline std::string escape_log_text(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    for (std::size_t i = 0; i < text.size();) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (c >= 0x20 && c < 0x7F) {
            out += static_cast<char>(c);
            ++i;
        } else if (c == '\n') {
            out += "\\n";
            ++i;
        } else if (c == '\r') {
            out += "\\r";
            ++i;
        } else if (c == '\t') {
            out += "\\t";
            ++i;
        } else if (c < 0x80) {
            log_text_detail::append_hex(out, c);
            ++i;
        } else {
            char32_t code = 0;
            const std::size_t length = log_text_detail::utf8_sequence(text, i, code);
            if (length == 0) {
                log_text_detail::append_hex(out, c);
                ++i;
            } else if (code <= 0x9F || code == 0x2028 || code == 0x2029) {
                for (std::size_t k = 0; k < length; ++k) {
                    log_text_detail::append_hex(out, static_cast<unsigned char>(text[i + k]));
                }
                i += length;
            } else {
                out.append(text.substr(i, length));
                i += length;
            }
        }
    }
    return out;
}

/// @p text between double quotes for a log line: `"` and `\` inside are written `\"`
/// and `\\`, the rest as escape_log_text() writes it; so the quotation ends where it
/// seems to, and `"\n"` inside it can only be an escaped newline.
[[nodiscard]] inline std::string quoted(std::string_view text) {
    std::string out = "\"";
    std::size_t start = 0;
    for (std::size_t i = 0; i <= text.size(); ++i) {
        if (i < text.size() && text[i] != '"' && text[i] != '\\') continue;
        out += escape_log_text(text.substr(start, i - start));
        if (i < text.size()) {
            out += '\\';
            out += text[i];
        }
        start = i + 1;
    }
    out += '"';
    return out;
}

}  // namespace fieldbridge::core
