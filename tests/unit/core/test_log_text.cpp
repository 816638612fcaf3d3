// Text from outside made safe for a log line (issue 24 item 4): no newline, no escape
// sequence, no byte that is not UTF-8 survives; everything else is kept.
#include <doctest/doctest.h>

#include <string>
#include <string_view>

#include "core/log_text.hpp"

using fieldbridge::core::escape_log_text;
using fieldbridge::core::needs_log_escape;
using fieldbridge::core::quoted;
using namespace std::string_literals;

TEST_CASE("printable ASCII and valid UTF-8 are kept as they are") {
    for (const std::string& text : {"reset"s, "gripper-1 at 17.0 mm"s, "Greifer \xC3\xBC\xE2\x82\xAC \xF0\x9F\x94\xA7"s,
                                   "C:\\path \"q\""s, ""s}) {
        CHECK(escape_log_text(text) == text);
        CHECK_FALSE(needs_log_escape(text));
    }
}

TEST_CASE("a newline cannot start a forged line") {
    const std::string forged = "x\n2026-01-01 00:00:00.000 [critical] FORGED";
    CHECK(escape_log_text(forged) == "x\\n2026-01-01 00:00:00.000 [critical] FORGED");
    CHECK(escape_log_text("a\r\nb\tc") == "a\\r\\nb\\tc");
    CHECK(needs_log_escape(forged));
}

TEST_CASE("other control characters, DEL and escape sequences become \\xHH") {
    CHECK(escape_log_text("\x1b[2J") == "\\x1B[2J");
    CHECK(escape_log_text(std::string_view("\0\x07\x7f", 3)) == "\\x00\\x07\\x7F");
    // C1 controls (CSI U+009B, NEL U+0085) and the Unicode line separators, in UTF-8.
    CHECK(escape_log_text("a\xC2\x9B" "2Jb") == "a\\xC2\\x9B2Jb");
    CHECK(escape_log_text("\xC2\x85") == "\\xC2\\x85");
    CHECK(escape_log_text("\xE2\x80\xA8|\xE2\x80\xA9") == "\\xE2\\x80\\xA8|\\xE2\\x80\\xA9");
}

TEST_CASE("bytes that are not UTF-8 become \\xHH, one by one") {
    CHECK(escape_log_text("\x9B" "2J") == "\\x9B2J");                     // a bare C1 byte
    CHECK(escape_log_text("\xC3") == "\\xC3");                             // cut sequence
    CHECK(escape_log_text("\xC0\x8A") == "\\xC0\\x8A");                     // overlong newline
    CHECK(escape_log_text("\xED\xA0\x80") == "\\xED\\xA0\\x80");            // surrogate
    CHECK(escape_log_text("\xF4\x90\x80\x80") == "\\xF4\\x90\\x80\\x80");   // above U+10FFFF
    CHECK(escape_log_text("\xFF\xC3\xBC") == "\\xFF\xC3\xBC");             // a good character after a bad byte
}

TEST_CASE("quoted() escapes the quote and the backslash, and the rest like every log line") {
    CHECK(quoted("reset") == "\"reset\"");
    CHECK(quoted("a\"b\\c") == "\"a\\\"b\\\\c\"");
    CHECK(quoted("x' to gripper-1: ok\n") == "\"x' to gripper-1: ok\\n\"");
    CHECK(quoted("") == "\"\"");
    CHECK(quoted("\"") == "\"\\\"\"");
}
