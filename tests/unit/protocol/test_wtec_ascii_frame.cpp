// WTEC-485 ASCII frame codec (seed 003, section 1.2): encode, decode_frame_body,
// scan_frame, at the boundaries: empty, truncated, oversize, bad CRC, bad hex,
// garbage, bare CR/LF, frames back to back.

#include <doctest/doctest.h>

#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"
#include "protocol/wtec_ascii_frame.hpp"
#include "wtec_test_support.hpp"

namespace {

using fieldbridge::protocol::ByteView;
using fieldbridge::protocol::DecodeError;
using fieldbridge::protocol::DecodeResult;
using fieldbridge::protocol::DecodeStatus;
namespace wtec = fieldbridge::protocol::wtec;

using wtec_test::bytes;
using wtec_test::describe;
using wtec_test::malformed;

const std::string crlf = "\r\n";
// Frames from the manual whose CRC verifies (tests/vectors/vectors.yaml).
const std::string read_version = ">01A63D8";
const std::string version_reply = ">01ACstep [A]1.623921";
const std::string homing_reply = ">01BFC0000753000030D40000003E8411000000C800989680621D";

bool is_upper_hex(char c) { return (c >= '0' && c <= '9') || (c >= 'A' && c <= 'F'); }

/// Another character of the same class, so a change stays syntactically valid.
char other_char(char c) {
    if (is_upper_hex(c)) return c == '0' ? '1' : '0';
    if (c >= 'a' && c <= 'z') return c == 'a' ? 'b' : 'a';
    if (c >= 'A' && c <= 'Z') return c == 'Y' ? 'Z' : 'Y';
    return c == ' ' ? '.' : ' ';
}

}  // namespace

TEST_CASE("wtec frame: hex helpers are upper case only") {
    CHECK(wtec::parse_hex("0") == 0U);
    CHECK(wtec::parse_hex("FFFFFFFF") == 0xFFFFFFFFU);
    CHECK(wtec::parse_hex("00989680") == 0x989680U);
    CHECK_FALSE(wtec::parse_hex("").has_value());
    CHECK_FALSE(wtec::parse_hex("123456789").has_value());
    CHECK_FALSE(wtec::parse_hex("ff").has_value());
    CHECK_FALSE(wtec::parse_hex("0G").has_value());
    CHECK_FALSE(wtec::parse_hex(" 1").has_value());
    std::string out;
    wtec::append_hex(out, 0x3C, 2);
    wtec::append_hex(out, 0xFFFFFFFD, 8);
    wtec::append_hex(out, 0xAB, 1);
    CHECK(out == "3CFFFFFFFDB");
    CHECK(wtec::is_command_char('$'));
    CHECK(wtec::is_command_char('z'));
    CHECK_FALSE(wtec::is_command_char('1'));
    CHECK_FALSE(wtec::is_command_char('>'));
    CHECK(wtec::is_data_char(' '));
    CHECK(wtec::is_data_char('~'));
    CHECK_FALSE(wtec::is_data_char('>'));
    CHECK_FALSE(wtec::is_data_char('\r'));
    CHECK_FALSE(wtec::is_data_char('\x7F'));
}

TEST_CASE("wtec frame: encode matches the manual's frames") {
    CHECK(wtec::encode_frame_body({0x01, 'A', ""}) == read_version);
    CHECK(wtec::encode_frame({0x01, 'A', ""}) == read_version + crlf);
    CHECK(wtec::encode_frame_body({0x00, '$', ""}) == ">00$D819");
    CHECK(wtec::encode_frame_body({0x0A, 'i', ""}) == ">0AiBDFD");
    CHECK(wtec::encode_frame_body({0x01, 'A', "Cstep [A]1.62"}) == version_reply);
    // Address 0xFD, the highest device address, is written upper case.
    CHECK(wtec::encode_frame_body({0xFD, 'G', ""}).substr(0, 4) == ">FDG");
}

TEST_CASE("wtec frame: encode refuses what cannot be sent") {
    CHECK_THROWS_AS((void)wtec::encode_frame({1, '1', ""}), fieldbridge::core::InvalidArgument);
    CHECK_THROWS_AS((void)wtec::encode_frame({1, '\0', ""}), fieldbridge::core::InvalidArgument);
    CHECK_THROWS_AS((void)wtec::encode_frame({1, 'A', "a>b"}), fieldbridge::core::InvalidArgument);
    CHECK_THROWS_AS((void)wtec::encode_frame({1, 'A', "a\rb"}), fieldbridge::core::InvalidArgument);
    CHECK_THROWS_AS((void)wtec::encode_frame({1, 'A', std::string(wtec::max_data_size + 1, '0')}),
                    fieldbridge::core::InvalidArgument);
    // The largest frame is exactly max_frame_size characters and scans back.
    const std::string largest = wtec::encode_frame({1, 'A', std::string(wtec::max_data_size, '7')});
    CHECK(largest.size() == wtec::max_frame_size);
    const auto r = wtec::scan_frame(bytes(largest));
    REQUIRE(r.complete());
    CHECK(r.consumed == largest.size());
    CHECK(r.value.data == std::string(wtec::max_data_size, '7'));
}

TEST_CASE("wtec frame: decode_frame_body accepts the manual's frames") {
    auto r = wtec::decode_frame_body(homing_reply);
    REQUIRE(r.complete());
    CHECK(r.consumed == homing_reply.size());
    CHECK(r.value == wtec::AsciiFrame{1, 'B', "FC0000753000030D40000003E8411000000C800989680"});
    r = wtec::decode_frame_body(version_reply);
    REQUIRE(r.complete());
    CHECK(r.value.data == "Cstep [A]1.62");
}

TEST_CASE("wtec frame: decode_frame_body boundaries") {
    CHECK(describe(wtec::decode_frame_body("")) == malformed(DecodeError::bad_framing));
    CHECK(describe(wtec::decode_frame_body("01A63D8")) == malformed(DecodeError::bad_framing));
    CHECK(describe(wtec::decode_frame_body(">")) == malformed(DecodeError::bad_length));
    CHECK(describe(wtec::decode_frame_body(">01A63D")) == malformed(DecodeError::bad_length));
    CHECK(describe(wtec::decode_frame_body(read_version + crlf)) == malformed(DecodeError::bad_framing));

    SUBCASE("every truncation is rejected") {
        for (const std::string& body : {read_version, version_reply, homing_reply}) {
            for (std::size_t n = 0; n < body.size(); ++n) {
                CAPTURE(n);
                CHECK(wtec::decode_frame_body(std::string_view(body).substr(0, n)).malformed());
            }
        }
    }
    SUBCASE("over the maximum") {
        const std::string largest =
            wtec::encode_frame_body({1, 'A', std::string(wtec::max_data_size, '1')});
        CHECK(wtec::decode_frame_body(largest).complete());
        // One more data character: the length is checked before the CRC digits.
        const std::string body = ">01A" + std::string(wtec::max_data_size + 1, '1') + "0000";
        CHECK(describe(wtec::decode_frame_body(body)) == malformed(DecodeError::oversize));
    }
    SUBCASE("bad hex in address and CRC, lower case included") {
        CHECK(describe(wtec::decode_frame_body(">0GA63D8")) == malformed(DecodeError::bad_hex));
        CHECK(describe(wtec::decode_frame_body("> 1A63D8")) == malformed(DecodeError::bad_hex));
        CHECK(describe(wtec::decode_frame_body(">01A63DX")) == malformed(DecodeError::bad_hex));
        CHECK(describe(wtec::decode_frame_body(">01A63d8")) == malformed(DecodeError::bad_hex));
        CHECK(describe(wtec::decode_frame_body(">0aiBDFD")) == malformed(DecodeError::bad_hex));
        CHECK(describe(wtec::decode_frame_body(">0AiBDFD")) == "complete");
        CHECK(describe(wtec::decode_frame_body(">0AiBDfD")) == malformed(DecodeError::bad_hex));
        for (std::size_t pos : {1U, 2U, 4U, 5U, 6U, 7U}) {
            std::string body = read_version;
            body[pos] = 'g';
            CAPTURE(body);
            CHECK(describe(wtec::decode_frame_body(body)) == malformed(DecodeError::bad_hex));
        }
    }
    SUBCASE("command byte must be a letter or $") {
        CHECK(describe(wtec::decode_frame_body(">01163D8")) == malformed(DecodeError::bad_framing));
        CHECK(describe(wtec::decode_frame_body(">01#63D8")) == malformed(DecodeError::bad_framing));
        CHECK(describe(wtec::decode_frame_body(">01 63D8")) == malformed(DecodeError::bad_framing));
    }
    SUBCASE("data characters must be printable and not '>'") {
        CHECK(describe(wtec::decode_frame_body(">01A\x01" "63D8")) == malformed(DecodeError::bad_framing));
        CHECK(describe(wtec::decode_frame_body(">01A>63D8")) == malformed(DecodeError::bad_framing));
        CHECK(describe(wtec::decode_frame_body(">01A\x80" "63D8")) == malformed(DecodeError::bad_framing));
    }
    SUBCASE("changing any one character breaks the CRC") {
        for (const std::string& body : {read_version, version_reply, homing_reply}) {
            for (std::size_t pos = 1; pos < body.size(); ++pos) {
                std::string changed = body;
                // The command letter stays a letter; every other character keeps its class.
                changed[pos] = pos == 3 ? (body[pos] == 'Y' ? 'Z' : 'Y') : other_char(body[pos]);
                CAPTURE(changed);
                CHECK(describe(wtec::decode_frame_body(changed)) == malformed(DecodeError::bad_crc));
            }
        }
    }
}

TEST_CASE("wtec frame: scan_frame") {
    SUBCASE("empty and every truncation need more") {
        CHECK(describe(wtec::scan_frame({})) == "need_more");
        for (const std::string& body : {read_version, version_reply, homing_reply}) {
            const std::string text = body + crlf;
            for (std::size_t n = 1; n < text.size(); ++n) {
                const auto r = wtec::scan_frame(bytes(std::string_view(text).substr(0, n)));
                CAPTURE(n);
                CHECK(describe(r) == "need_more");
                CHECK(r.consumed == 0);
            }
            const auto r = wtec::scan_frame(bytes(text));
            REQUIRE(r.complete());
            CHECK(r.consumed == text.size());
        }
    }
    SUBCASE("garbage before '>' is counted in consumed") {
        const std::string text = std::string("\x00\xFF noise\r\n", 10) + read_version + crlf;
        const auto r = wtec::scan_frame(bytes(text));
        REQUIRE(r.complete());
        CHECK(r.consumed == text.size());
        CHECK(r.value == wtec::AsciiFrame{1, 'A', ""});
        // Garbage then a partial frame waits for the rest.
        CHECK(describe(wtec::scan_frame(bytes("xx>01A6"))) == "need_more");
    }
    SUBCASE("a buffer of garbage only is dropped whole") {
        const std::string text = "abc\r\n\x01";
        const auto r = wtec::scan_frame(bytes(text));
        CHECK(describe(r) == malformed(DecodeError::bad_framing));
        CHECK(r.consumed == text.size());
    }
    SUBCASE("two frames back to back") {
        const std::string first = read_version + crlf;
        const std::string second = version_reply + crlf;
        const std::string text = first + second;
        const auto r1 = wtec::scan_frame(bytes(text));
        REQUIRE(r1.complete());
        CHECK(r1.consumed == first.size());
        CHECK(r1.value.command == 'A');
        CHECK(r1.value.data.empty());
        const auto r2 = wtec::scan_frame(bytes(text).subspan(r1.consumed));
        REQUIRE(r2.complete());
        CHECK(r2.consumed == second.size());
        CHECK(r2.value.data == "Cstep [A]1.62");
    }
    SUBCASE("oversize without CR LF") {
        // 62 characters: a CR and LF may still follow and make 64.
        std::string text = ">01A" + std::string(wtec::max_frame_size - 6, '0');
        CHECK(describe(wtec::scan_frame(bytes(text))) == "need_more");
        CHECK(describe(wtec::scan_frame(bytes(text + "\r"))) == "need_more");
        // 63 characters and no CR: the LF could only come at 65.
        text += '0';
        auto r = wtec::scan_frame(bytes(text));
        CHECK(describe(r) == malformed(DecodeError::oversize));
        CHECK(r.consumed == wtec::max_frame_size - 1);
        r = wtec::scan_frame(bytes(text + "\r\n" + read_version + crlf));
        CHECK(describe(r) == malformed(DecodeError::oversize));
        CHECK(r.consumed == wtec::max_frame_size - 1);
        // A long run of data: dropped in one piece, from the '>' on.
        text = "xx>01A" + std::string(200, '0');
        r = wtec::scan_frame(bytes(text));
        CHECK(describe(r) == malformed(DecodeError::oversize));
        CHECK(r.consumed == 2 + wtec::max_frame_size - 1);
        // Garbage before '>' does not count towards the maximum of the largest frame.
        text = std::string(100, 'x') + wtec::encode_frame({1, 'A', std::string(wtec::max_data_size, '5')});
        r = wtec::scan_frame(bytes(text));
        REQUIRE(r.complete());
        CHECK(r.consumed == text.size());
    }
    SUBCASE("bare CR or LF") {
        auto r = wtec::scan_frame(bytes(read_version + "\rX"));
        CHECK(describe(r) == malformed(DecodeError::bad_framing));
        CHECK(r.consumed == read_version.size() + 1);
        r = wtec::scan_frame(bytes(read_version + "\n"));
        CHECK(describe(r) == malformed(DecodeError::bad_framing));
        CHECK(r.consumed == read_version.size() + 1);
        r = wtec::scan_frame(bytes(">01\n"));
        CHECK(describe(r) == malformed(DecodeError::bad_framing));
        CHECK(r.consumed == 4);
        CHECK(describe(wtec::scan_frame(bytes(read_version + "\r"))) == "need_more");
        r = wtec::scan_frame(bytes(read_version + "\r\r\n"));
        CHECK(describe(r) == malformed(DecodeError::bad_framing));
        CHECK(r.consumed == read_version.size() + 1);
    }
    SUBCASE("a second '>' restarts the frame") {
        const std::string text = ">01A6" + read_version + crlf;
        auto r = wtec::scan_frame(bytes(text));
        CHECK(describe(r) == malformed(DecodeError::bad_framing));
        CHECK(r.consumed == 5);
        r = wtec::scan_frame(bytes(text).subspan(5));
        REQUIRE(r.complete());
        CHECK(r.value == wtec::AsciiFrame{1, 'A', ""});
    }
    SUBCASE("non-printable byte inside a frame") {
        const auto r = wtec::scan_frame(bytes(std::string(">01A\x00" "63D8\r\n", 11)));
        CHECK(describe(r) == malformed(DecodeError::bad_framing));
        CHECK(r.consumed == 5);
    }
    SUBCASE("a terminated frame with bad content is dropped whole") {
        const std::string bad_crc = ">01A63D9\r\n";
        auto r = wtec::scan_frame(bytes(bad_crc + read_version + crlf));
        CHECK(describe(r) == malformed(DecodeError::bad_crc));
        CHECK(r.consumed == bad_crc.size());
        r = wtec::scan_frame(bytes(">\r\n"));
        CHECK(describe(r) == malformed(DecodeError::bad_length));
        CHECK(r.consumed == 3);
        r = wtec::scan_frame(bytes(">01A63d8\r\n"));
        CHECK(describe(r) == malformed(DecodeError::bad_hex));
        CHECK(r.consumed == 10);
    }
}

TEST_CASE("wtec frame: a noisy stream resynchronises on every good frame") {
    const std::vector<std::string> good = {read_version + crlf, version_reply + crlf,
                                           homing_reply + crlf, ">0AiBDFD\r\n"};
    std::string stream;
    for (const auto& frame : good) {
        stream += "\x13\x11 junk";
        stream += ">01A6";                   // cut short by the next '>'
        stream += frame;
        stream += ">01A63D9\r\n";            // bad CRC
        stream += std::string(70, 'Z');      // no '>' at all
        stream += ">01" + std::string(70, '0');  // oversize
    }
    std::vector<wtec::AsciiFrame> seen;
    ByteView rest = bytes(stream);
    int guard = 0;
    while (!rest.empty() && ++guard < 1000) {
        const auto r = wtec::scan_frame(rest);
        if (r.need_more()) break;
        REQUIRE(r.consumed > 0);
        REQUIRE(r.consumed <= rest.size());
        if (r.complete()) seen.push_back(r.value);
        rest = rest.subspan(r.consumed);
    }
    REQUIRE(seen.size() == good.size());
    for (std::size_t i = 0; i < good.size(); ++i) {
        CHECK(wtec::encode_frame(seen[i]) == good[i]);
    }
}
