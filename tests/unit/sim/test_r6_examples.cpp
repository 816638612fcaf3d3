// Huacheng R6: every example request/response of the manual (seed 004), as printed
// (MBAP header included); the 7-byte MBAP header is stripped and the PDUs compared.
#include <doctest/doctest.h>

#include "models/r6_model.hpp"
#include "sim_test_support.hpp"

namespace fieldbridge::test {
namespace {

constexpr std::size_t mbap_size = 7;

protocol::Bytes pdu_of(std::string_view mbap_frame_hex) {
    const protocol::Bytes frame = hex(mbap_frame_hex);
    REQUIRE(frame.size() > mbap_size);
    return protocol::Bytes(frame.begin() + mbap_size, frame.end());
}

/// The model's response PDU to the printed request frame, as hex.
std::string ask_framed(sim::R6Model& r6, std::string_view mbap_request, Clock::time_point now) {
    return hex_of(r6.handle_pdu(pdu_of(mbap_request), now));
}

std::string expected(std::string_view mbap_response) { return hex_of(pdu_of(mbap_response)); }

}  // namespace

TEST_CASE("r6: section 3.1 read examples") {
    SimClock clock;
    sim::R6Model r6;
    const auto now = clock.now();
    // 3.1.1 version length
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 00 00 00 01", now) == expected("00 00 00 00 00 05 01 03 02 00 29"));
    // 3.1.2 version string. The printed reply lists 41 data bytes (40 characters and the
    // NUL) after the byte count 0x2a = 42 = 21 registers: the last register's padding
    // byte is missing from the print, and is the final 00 here.
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 00 01 00 15", now) ==
          expected("00 00 00 00 00 2c 01 03 2a"
                   " 41 4d 38 2d 51 43 2d 52 58 45 2d 37 2e 38 2e 30 32 2d 62 61 74 65 37 5f"
                   " 46 41 4b 45 5f 54 47 46 5f 45 4e 43 4f 44 45 52 00") + " 00");
    // 3.1.3 counter count and list
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 00 82 00 01", now) == expected("00 00 00 00 00 05 01 03 02 00 02"));
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 00 83 00 04", now) ==
          expected("00 00 00 00 00 0b 01 03 08 00 00 00 00 00 00 00 01"));
    // Example 2 (no reply printed): from counter 1, the missing second one padded with FF.
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 00 85 00 04", now) ==
          expected("00 00 00 00 00 0b 01 03 08 00 00 00 01 FF FF FF FF"));
    // 3.1.4 select counter 1, read ID / target / current
    CHECK(ask_framed(r6, "00 00 00 00 00 0B 01 10 08 83 00 02 04 00 00 00 01", now) ==
          expected("00 00 00 00 00 06 01 10 08 83 00 02"));
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 08 83 00 06", now) ==
          expected("00 00 00 00 00 0f 01 03 0c 00 00 00 01 00 00 00 0a 00 00 00 05"));
    // 3.1.5 mode
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 08 89 00 01", now) == expected("00 00 00 00 00 05 01 03 02 00 03"));
    // 3.1.6 IO boards, inputs, outputs
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 08 8a 00 01", now) == expected("00 00 00 00 00 05 01 03 02 00 01"));
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 08 8b 00 02", now) == expected("00 00 00 00 00 07 01 03 04 00 00 00 00"));
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 08 b3 00 02", now) == expected("00 00 00 00 00 07 01 03 04 00 00 00 00"));
    // 3.1.7 / 3.1.8 axes
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 08 db 00 01", now) == expected("00 00 00 00 00 05 01 03 02 00 06"));
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 08 dc 00 02", now) == expected("00 00 00 00 00 07 01 03 04 00 00 00 00"));
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 08 dc 00 04", now) == hex_of(hex("03 08 00 00 00 00 00 00 00 00")));
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 08 de 00 02", now) == hex_of(hex("03 04 00 00 00 00")));
    // 3.1.9 world coordinates
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 09 1c 00 02", now) == expected("00 00 00 00 00 07 01 03 04 00 00 00 00"));
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 09 1c 00 04", now) == hex_of(hex("03 08 00 00 00 00 00 00 00 00")));
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 09 1e 00 02", now) == hex_of(hex("03 04 00 00 00 00")));
    // 3.1.11 cycle times
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 09 5d 00 04", now) ==
          expected("00 00 00 00 00 0b 01 03 08 00 00 00 00 00 00 00 00"));
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 09 61 00 04", now) ==
          expected("00 00 00 00 00 0b 01 03 08 00 00 00 00 00 00 00 00"));
    // 3.1.12 host address, 3.1.13 torque, 3.1.14 speed
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 09 65 00 01", now) == expected("00 00 00 00 00 05 01 03 02 00 01"));
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 09 66 00 01", now) == expected("00 00 00 00 00 05 01 03 02 00 00"));
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 09 86 00 01", now) == expected("00 00 00 00 00 05 01 03 02 00 00"));
}

TEST_CASE("r6: examples that need a state (alarm 805, moving, two IO boards)") {
    SimClock clock;
    sim::R6Model r6;
    // 3.1.10 alarm number 0x0325
    REQUIRE(r6.control("alarm 805", clock.now()).empty());
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 09 5c 00 01", clock.now()) ==
          expected("00 00 00 00 00 05 01 03 02 03 25"));
    REQUIRE(r6.control("clear", clock.now()).empty());
    // 3.1.15 move state 1 once started
    REQUIRE(r6.control("start", clock.now()).empty());
    clock.advance_ms(100);
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 09 a6 00 01", clock.now()) ==
          expected("00 00 00 00 00 05 01 03 02 00 01"));
    // 3.1.6 examples 2 and 3 read the second board: valid with two boards.
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 08 8d 00 02", clock.now()) == hex_of(hex("83 02")));
    REQUIRE(r6.control("io_boards 2", clock.now()).empty());
    REQUIRE(r6.control("input 1 0x00010002", clock.now()).empty());
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 08 8b 00 04", clock.now()) == hex_of(hex("03 08 00 00 00 00 00 01 00 02")));
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 08 8d 00 02", clock.now()) == hex_of(hex("03 04 00 01 00 02")));
}

TEST_CASE("r6: section 3.2 and 3.3 write examples, and what they change") {
    SimClock clock;
    sim::R6Model r6;
    const auto now = clock.now();
    // 3.2.1 stop, 3.2.2 global speed: the reply is the request
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 06 4e 20 00 01", now) == expected("00 00 00 00 00 06 01 06 4e 20 00 01"));
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 06 4e e8 00 64", now) == expected("00 00 00 00 00 06 01 06 4e e8 00 64"));
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 4e e8 00 01", now) == hex_of(hex("03 02 00 64")));
    // 3.3.1 outputs of board 0
    CHECK(ask_framed(r6, "00 00 00 00 00 0B 01 10 08 b3 00 02 04 00 00 00 01", now) ==
          expected("00 00 00 00 00 06 01 10 08 b3 00 02"));
    // 3.3.2 counter 1 current = 8
    CHECK(ask_framed(r6, "00 00 00 00 00 13 01 10 4e 52 00 06 0c 00 00 00 01 00 00 00 00 00 00 00 08", now) ==
          expected("00 00 00 00 00 06 01 10 4e 52 00 06"));
    // 3.3.3 board 0 output 1 on
    CHECK(ask_framed(r6, "00 00 00 00 00 0d 01 10 4e 58 00 03 06 00 00 00 01 00 01", now) ==
          expected("00 00 00 00 00 06 01 10 4e 58 00 03"));
    // 3.3.4 parameters, examples 1-3
    CHECK(ask_framed(r6, "00 00 00 00 00 0b 01 10 4f 4c 00 02 04 00 00 00 64", now) ==
          expected("00 00 00 00 00 06 01 10 4f 4c 00 02"));
    CHECK(ask_framed(r6, "00 00 00 00 00 0b 01 10 4f 4e 00 02 04 00 00 00 64", now) == hex_of(hex("10 4f 4e 00 02")));
    CHECK(ask_framed(r6, "00 00 00 00 00 0f 01 10 4f 4c 00 04 08 00 00 00 64 00 00 00 C8", now) ==
          hex_of(hex("10 4f 4c 00 04")));
    // 3.3.5 data source 100 (6 values a point, axes 1, 2, 6), then 2 points. The manual
    // prints the first reply as "... 10 4f 4c 00 02"; its table gives 10 75 32 00 03.
    CHECK(ask_framed(r6, "00 00 00 00 00 0b 01 10 75 32 00 03 06 00 64 00 06 00 23", now) ==
          hex_of(hex("10 75 32 00 03")));
    CHECK(ask_framed(r6, "00 00 00 00 00 0b 01 10 75 35 00 1A 34 00 02 00 01 00 00 00 01 00 00 00 02 00 00 00 03 00"
                  " 00 00 04 00 00 00 05 00 00 00 06 00 00 00 07 00 00 00 08 00 00 00 09 00 00 00 0A 00 00 00"
                  " 0B 00 00 00 0C",
              now) == hex_of(hex("10 75 35 00 1A")));

    // What they changed.
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 08 b3 00 02", now) == hex_of(hex("03 04 00 00 00 03")));
    CHECK(ask_framed(r6, "00 00 00 00 00 0B 01 10 08 83 00 02 04 00 00 00 01", now) == hex_of(hex("10 08 83 00 02")));
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 08 83 00 06", now) ==
          hex_of(hex("03 0c 00 00 00 01 00 00 00 0a 00 00 00 08")));
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 4f 4c 00 04", now) == hex_of(hex("03 08 00 00 00 64 00 00 00 C8")));
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 75 30 00 02", now) == hex_of(hex("03 04 00 64 00 02")));
    CHECK(ask_framed(r6, "00 00 00 00 00 06 01 03 75 32 00 05", now) == hex_of(hex("03 0A 00 64 00 06 00 23 00 02 00 01")));
}

}  // namespace fieldbridge::test
