// WTEC-485 ASCII typed commands (seed 003, "指令集"): every command and reply,
// round trips, strict reply parsing, and a fixed-seed fuzz loop.

#include <doctest/doctest.h>

#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"
#include "protocol/wtec_ascii_commands.hpp"
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

const wtec::HomingParams homing{0xFD, 0x12345678, 0x9ABCDEF0, 0x0000FFFF, 0x7F, 0xE, 0xC8, 0x989680};
const wtec::GripperParams gripper{0xFFFFFFFF, 0x3F, 0xFF, 0x0A, 0x1};
const wtec::DriverParams driver{0x2710, 0x7A120, 0x78, 0x1, 0x03, 0x02, 0x2710, 0x5DC, 0x0};
const wtec::Pid pid{0x0080, 0x0000, 0xFFFF};
const wtec::ReleaseParams release{0x5C, 0xFF};

/// One command of every kind, its letter, its request data width, a reply that
/// answers it and the reply data width.
struct Case {
    wtec::Command command;
    char letter;
    std::size_t request_width;
    wtec::Reply reply;
    std::size_t reply_width;
};

const std::vector<Case>& cases() {
    static const std::vector<Case> all = {
        {wtec::ReadVersion{}, 'A', 0, wtec::Version{"Cstep [A]1.62"}, 13},
        {wtec::ReadStations{}, '$', 0, wtec::Station{0x07}, 2},
        {wtec::SetMotorEnable{true}, 'a', 1, wtec::Ack{}, 0},
        {wtec::ReadHoming{}, 'B', 0, homing, 45},
        {wtec::WriteHoming{homing}, 'b', 45, wtec::Ack{}, 0},
        {wtec::SetPeakCurrent{0x3C}, 'C', 2, wtec::Ack{}, 0},
        {wtec::SetTarget{-123456}, 'D', 8, wtec::Ack{}, 0},
        {wtec::QueryGripState{}, 'd', 0, wtec::StateCode{wtec::grip_state::motor_released}, 2},
        {wtec::GripperAction{wtec::GripAction::toggle}, 'E', 1, wtec::Ack{}, 0},
        {wtec::Home{}, 'G', 0, wtec::Ack{}, 0},
        {wtec::QueryHoming{}, 'g', 0, wtec::StateCode{wtec::homing_state::homing}, 2},
        {wtec::ReadRunning{}, 'I', 0, wtec::RunningValues{-3, 0x03, true, 0x05}, 13},
        {wtec::SetAddress{0xFD}, 'i', 2, wtec::Ack{}, 0},
        {wtec::ReadPid{}, 'P', 0, pid, 12},
        {wtec::WritePid{pid}, 'p', 12, wtec::Ack{}, 0},
        {wtec::ReadGripper{}, 'N', 0, gripper, 15},
        {wtec::WriteGripper{gripper}, 'n', 15, wtec::Ack{}, 0},
        {wtec::ReadDriver{}, 'R', 0, driver, 36},
        {wtec::WriteDriver{driver}, 'r', 36, wtec::Ack{}, 0},
        {wtec::SaveAll{}, 'U', 0, wtec::Ack{}, 0},
        {wtec::ReadRelease{}, 'W', 0, release, 30},
        {wtec::WriteRelease{release}, 'w', 30, wtec::Ack{}, 0},
        {wtec::CalibrateEncoder{}, 'Z', 0, wtec::Ack{}, 0},
    };
    return all;
}

constexpr std::uint8_t device = 0x07;

/// The address a reply to @p c comes from when the request went to `device`.
std::uint8_t reply_address(const wtec::Command& c) {
    if (const auto* set = std::get_if<wtec::SetAddress>(&c)) return set->new_address;
    return device;
}

/// The frame through the wire: encode_frame then scan_frame.
wtec::AsciiFrame over_the_wire(const wtec::AsciiFrame& frame) {
    const std::string text = wtec::encode_frame(frame);
    const auto r = wtec::scan_frame(bytes(text));
    REQUIRE(r.complete());
    REQUIRE(r.consumed == text.size());
    return r.value;
}

}  // namespace

TEST_CASE("wtec commands: the case table covers every command once") {
    REQUIRE(cases().size() == std::variant_size_v<wtec::Command>);
    std::vector<bool> seen(std::variant_size_v<wtec::Command>, false);
    for (const auto& c : cases()) {
        CHECK_FALSE(seen[c.command.index()]);
        seen[c.command.index()] = true;
    }
}

TEST_CASE("wtec commands: letters, widths and request round trips") {
    for (const auto& c : cases()) {
        CAPTURE(c.letter);
        CHECK(wtec::letter_of(c.command) == c.letter);
        const wtec::AsciiFrame frame = wtec::encode_command(device, c.command);
        CHECK(frame.command == c.letter);
        CHECK(frame.data.size() == c.request_width);
        // '$' always goes to the broadcast address (seed 003 command 2).
        CHECK(frame.address == (c.letter == '$' ? wtec::broadcast_address : device));
        const auto decoded = wtec::decode_command(over_the_wire(frame));
        REQUIRE(decoded.complete());
        CHECK(decoded.value == c.command);
    }
}

TEST_CASE("wtec commands: reply round trips") {
    for (const auto& c : cases()) {
        CAPTURE(c.letter);
        const wtec::AsciiFrame frame = wtec::encode_reply(device, c.command, c.reply);
        CHECK(frame.command == c.letter);
        CHECK(frame.address == reply_address(c.command));
        CHECK(frame.data.size() == c.reply_width);
        const auto decoded = wtec::decode_reply(device, c.command, over_the_wire(frame));
        REQUIRE(decoded.complete());
        CHECK(decoded.value == c.reply);
    }
}

TEST_CASE("wtec commands: field encodings") {
    CHECK(wtec::encode_command(1, wtec::SetTarget{-1}).data == "FFFFFFFF");
    CHECK(wtec::encode_command(1, wtec::SetTarget{std::numeric_limits<std::int32_t>::min()}).data ==
          "80000000");
    CHECK(wtec::encode_command(1, wtec::SetTarget{0x5C44}).data == "00005C44");
    CHECK(wtec::encode_command(1, wtec::SetMotorEnable{false}).data == "0");
    CHECK(wtec::encode_command(1, wtec::GripperAction{wtec::GripAction::release}).data == "2");
    CHECK(wtec::encode_command(1, wtec::WriteRelease{release}).data ==
          "5CFF" + std::string(26, '0'));
    CHECK(wtec::encode_command(1, wtec::WriteDriver{driver}).data ==
          "00002710" "0007A120" "78" "1" "03" "02" "2710" "000005DC" "0");
    auto target = wtec::decode_command({1, 'D', "80000000"});
    REQUIRE(target.complete());
    CHECK(std::get<wtec::SetTarget>(target.value).target == std::numeric_limits<std::int32_t>::min());
    target = wtec::decode_command({1, 'D', "7FFFFFFF"});
    REQUIRE(target.complete());
    CHECK(std::get<wtec::SetTarget>(target.value).target == std::numeric_limits<std::int32_t>::max());
}

TEST_CASE("wtec commands: wrong data length for every command") {
    for (const auto& c : cases()) {
        CAPTURE(c.letter);
        const std::string good = wtec::encode_command(device, c.command).data;
        wtec::AsciiFrame frame{device, c.letter, good + "0"};
        CHECK(describe(wtec::decode_command(frame)) == malformed(DecodeError::bad_length));
        if (!good.empty()) {
            frame.data = good.substr(0, good.size() - 1);
            CHECK(describe(wtec::decode_command(frame)) == malformed(DecodeError::bad_length));
            frame.data.clear();
            CHECK(describe(wtec::decode_command(frame)) == malformed(DecodeError::bad_length));
        }

        const wtec::AsciiFrame reply = wtec::encode_reply(device, c.command, c.reply);
        frame = reply;
        frame.data += "00";  // two, so that an `E` reply is not mistaken for an echo
        CHECK(describe(wtec::decode_reply(device, c.command, frame)) == malformed(DecodeError::bad_length));
        if (!reply.data.empty()) {
            frame.data = reply.data.substr(0, reply.data.size() - 1);
            // A 12-character version is legal (the prose's width); 11 is not.
            if (c.letter == 'A') frame.data.pop_back();
            CHECK(describe(wtec::decode_reply(device, c.command, frame)) ==
                  malformed(DecodeError::bad_length));
        }
    }
}

TEST_CASE("wtec commands: bad hex in every field, lower case included") {
    for (const auto& c : cases()) {
        CAPTURE(c.letter);
        const std::string good = wtec::encode_command(device, c.command).data;
        for (std::size_t pos = 0; pos < good.size(); ++pos) {
            CAPTURE(pos);
            for (const char bad : {'G', 'a', 'f', ' ', '-'}) {
                std::string data = good;
                data[pos] = bad;
                CHECK(describe(wtec::decode_command({device, c.letter, data})) ==
                      malformed(DecodeError::bad_hex));
            }
        }
        if (c.letter == 'A') continue;  // the version is text, not hex
        const wtec::AsciiFrame reply = wtec::encode_reply(device, c.command, c.reply);
        for (std::size_t pos = 0; pos < reply.data.size(); ++pos) {
            CAPTURE(pos);
            for (const char bad : {'G', 'c', ' '}) {
                wtec::AsciiFrame frame = reply;
                frame.data[pos] = bad;
                CHECK(describe(wtec::decode_reply(device, c.command, frame)) ==
                      malformed(DecodeError::bad_hex));
            }
        }
    }
    // Lower case survives the frame level (data is free text) and is refused by type.
    const auto frame = over_the_wire({1, 'C', "3c"});
    CHECK(describe(wtec::decode_command(frame)) == malformed(DecodeError::bad_hex));
}

TEST_CASE("wtec commands: wrong letter and wrong address in replies") {
    for (const auto& c : cases()) {
        CAPTURE(c.letter);
        wtec::AsciiFrame frame = wtec::encode_reply(device, c.command, c.reply);
        wtec::AsciiFrame other = frame;
        other.command = c.letter == 'Z' ? 'A' : 'Z';
        CHECK(describe(wtec::decode_reply(device, c.command, other)) ==
              malformed(DecodeError::unexpected_reply));
        // Upper/lower case letters are different commands ('B' read, 'b' write).
        other.command = static_cast<char>(c.letter ^ 0x20);
        if (c.letter != '$') {
            CHECK(describe(wtec::decode_reply(device, c.command, other)) ==
                  malformed(DecodeError::unexpected_reply));
        }
        if (c.letter == '$') continue;  // any device answers '$'
        other = frame;
        other.address = static_cast<std::uint8_t>(frame.address - 1);
        CHECK(describe(wtec::decode_reply(device, c.command, other)) ==
              malformed(DecodeError::wrong_address));
    }
}

TEST_CASE("wtec commands: unknown letters and out-of-range values") {
    for (const char letter : {'X', 'e', 'z', 'Q', 'c'}) {
        CAPTURE(letter);
        CHECK(describe(wtec::decode_command({1, letter, ""})) == malformed(DecodeError::wrong_function));
    }
    CHECK(describe(wtec::decode_command({1, 'a', "2"})) == malformed(DecodeError::bad_value));
    CHECK(describe(wtec::decode_command({1, 'E', "0"})) == malformed(DecodeError::bad_value));
    CHECK(describe(wtec::decode_command({1, 'E', "4"})) == malformed(DecodeError::bad_value));
    CHECK(describe(wtec::decode_command({1, 'i', "00"})) == malformed(DecodeError::bad_value));
    CHECK(describe(wtec::decode_command({1, 'i', "FE"})) == malformed(DecodeError::bad_value));
    CHECK(describe(wtec::decode_command({1, 'i', "01"})) == "complete");
    CHECK(describe(wtec::decode_reply(1, wtec::ReadRunning{}, {1, 'I', "FFFFFFFD03205"})) ==
          malformed(DecodeError::bad_value));
    CHECK(describe(wtec::decode_reply(1, wtec::ReadRunning{}, {1, 'I', "FFFFFFFD03005"})) == "complete");
    // '$': the station in the data repeats the replying address; 00 never replies.
    CHECK(describe(wtec::decode_reply(0, wtec::ReadStations{}, {2, '$', "03"})) ==
          malformed(DecodeError::bad_value));
    CHECK(describe(wtec::decode_reply(0, wtec::ReadStations{}, {0, '$', "00"})) ==
          malformed(DecodeError::wrong_address));
    CHECK(describe(wtec::decode_reply(0, wtec::ReadStations{}, {0xFE, '$', "FE"})) ==
          malformed(DecodeError::wrong_address));
    // 'A': 12 or 13 printable characters.
    CHECK(describe(wtec::decode_reply(1, wtec::ReadVersion{}, {1, 'A', "Cstep[A]1.62"})) == "complete");
    CHECK(describe(wtec::decode_reply(1, wtec::ReadVersion{}, {1, 'A', "Cstep [A]1.6\x01"})) ==
          malformed(DecodeError::bad_value));
}

TEST_CASE("wtec commands: E replies: acknowledgement or not-homed echo") {
    const wtec::Command grip = wtec::GripperAction{wtec::GripAction::grip};
    auto r = wtec::decode_reply(1, grip, {1, 'E', ""});
    REQUIRE(r.complete());
    CHECK(std::holds_alternative<wtec::Ack>(r.value));
    r = wtec::decode_reply(1, grip, {1, 'E', "1"});
    REQUIRE(r.complete());
    CHECK(std::holds_alternative<wtec::NotExecuted>(r.value));
    CHECK(describe(wtec::decode_reply(1, grip, {1, 'E', "2"})) == malformed(DecodeError::unexpected_reply));
    CHECK(describe(wtec::decode_reply(1, grip, {1, 'E', "11"})) == malformed(DecodeError::bad_length));
    CHECK(describe(wtec::decode_reply(1, grip, {1, 'E', "G"})) == malformed(DecodeError::bad_hex));
    for (const auto action : {wtec::GripAction::grip, wtec::GripAction::release, wtec::GripAction::toggle}) {
        const wtec::Command command = wtec::GripperAction{action};
        const auto echo = wtec::encode_reply(1, command, wtec::NotExecuted{});
        CHECK(echo == wtec::encode_command(1, command));
        r = wtec::decode_reply(1, command, echo);
        REQUIRE(r.complete());
        CHECK(std::holds_alternative<wtec::NotExecuted>(r.value));
    }
}

TEST_CASE("wtec commands: D replies: acknowledgement or not-executed echo") {
    // seed 003 command 7: D with an 8-digit target, acknowledged by >01D6018.
    const wtec::Command target = wtec::SetTarget{0x0001FFFF};
    auto r = wtec::decode_reply(1, target, {1, 'D', ""});
    REQUIRE(r.complete());
    CHECK(std::holds_alternative<wtec::Ack>(r.value));
    // The echo of the request (the refusal seed 003 documents for E) is recognised.
    const auto echo = wtec::encode_reply(1, target, wtec::NotExecuted{});
    CHECK(echo == wtec::encode_command(1, target));
    r = wtec::decode_reply(1, target, echo);
    REQUIRE(r.complete());
    CHECK(std::holds_alternative<wtec::NotExecuted>(r.value));
    // Any other data is not an echo of this request.
    CHECK(describe(wtec::decode_reply(1, target, {1, 'D', "0001FFFE"})) == malformed(DecodeError::unexpected_reply));
    CHECK(describe(wtec::decode_reply(1, target, {1, 'D', "0001FFF"})) == malformed(DecodeError::bad_length));
    CHECK(describe(wtec::decode_reply(1, target, {1, 'D', "0001FFFG"})) == malformed(DecodeError::bad_hex));
}

TEST_CASE("wtec commands: i replies come from the new address") {
    const wtec::Command set = wtec::SetAddress{0x0A};
    CHECK(wtec::decode_reply(1, set, {0x0A, 'i', ""}).complete());
    CHECK(describe(wtec::decode_reply(1, set, {0x01, 'i', ""})) == malformed(DecodeError::wrong_address));
}

TEST_CASE("wtec commands: W padding is encoded as zeros and accepted as any hex") {
    const std::string data = "5CFF" + std::string(25, '0') + "7";
    auto r = wtec::decode_reply(1, wtec::ReadRelease{}, {1, 'W', data});
    REQUIRE(r.complete());
    CHECK(r.value == wtec::Reply{release});
    auto c = wtec::decode_command({1, 'w', "5CFF" + std::string(26, 'F')});
    REQUIRE(c.complete());
    CHECK(c.value == wtec::Command{wtec::WriteRelease{release}});
}

TEST_CASE("wtec commands: encoders refuse values the wire cannot carry") {
    auto bad_homing = homing;
    bad_homing.sensor_mode = 0x10;
    CHECK_THROWS_AS((void)wtec::encode_command(1, wtec::WriteHoming{bad_homing}), fieldbridge::core::InvalidArgument);
    CHECK_THROWS_AS((void)wtec::encode_reply(1, wtec::ReadHoming{}, bad_homing), fieldbridge::core::InvalidArgument);
    auto bad_gripper = gripper;
    bad_gripper.home_at_power_up = 0x10;
    CHECK_THROWS_AS((void)wtec::encode_command(1, wtec::WriteGripper{bad_gripper}), fieldbridge::core::InvalidArgument);
    auto bad_driver = driver;
    bad_driver.multi_turn = 0x10;
    CHECK_THROWS_AS((void)wtec::encode_command(1, wtec::WriteDriver{bad_driver}), fieldbridge::core::InvalidArgument);
    bad_driver = driver;
    bad_driver.damping = 0xFF;
    CHECK_THROWS_AS((void)wtec::encode_command(1, wtec::WriteDriver{bad_driver}), fieldbridge::core::InvalidArgument);
    CHECK_THROWS_AS((void)wtec::encode_command(1, wtec::GripperAction{static_cast<wtec::GripAction>(7)}),
                    fieldbridge::core::InvalidArgument);
    CHECK_THROWS_AS((void)wtec::encode_command(1, wtec::SetAddress{0}), fieldbridge::core::InvalidArgument);
    CHECK_THROWS_AS((void)wtec::encode_command(1, wtec::SetAddress{0xFE}), fieldbridge::core::InvalidArgument);
    // A reply type that does not answer the command.
    CHECK_THROWS_AS((void)wtec::encode_reply(1, wtec::ReadPid{}, wtec::Ack{}), fieldbridge::core::InvalidArgument);
    CHECK_THROWS_AS((void)wtec::encode_reply(1, wtec::Home{}, pid), fieldbridge::core::InvalidArgument);
    CHECK_THROWS_AS((void)wtec::encode_reply(1, wtec::Home{}, wtec::NotExecuted{}), fieldbridge::core::InvalidArgument);
    CHECK_THROWS_AS((void)wtec::encode_reply(1, wtec::ReadVersion{}, wtec::Version{"1.62"}),
                    fieldbridge::core::InvalidArgument);
    CHECK_THROWS_AS((void)wtec::encode_reply(1, wtec::ReadStations{}, wtec::Station{2}),
                    fieldbridge::core::InvalidArgument);
}

TEST_CASE("wtec commands: fixed-seed fuzz through scan, decode_command and decode_reply") {
    std::mt19937 rng(0x57EC485U);  // fixed: the same 20000 buffers on every run
    const auto pick = [&rng](std::size_t n) {
        return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng);
    };
    std::vector<std::string> seeds;
    for (const auto& c : cases()) {
        seeds.push_back(wtec::encode_frame(wtec::encode_command(device, c.command)));
        seeds.push_back(wtec::encode_frame(wtec::encode_reply(device, c.command, c.reply)));
    }
    constexpr char alphabet_chars[] = ">\r\n0123456789ABCDEFabcdefGZz$ \x00\xFF";
    const std::string_view alphabet(alphabet_chars, sizeof alphabet_chars - 1);
    std::size_t frames = 0;
    std::size_t typed = 0;
    for (int round = 0; round < 20000; ++round) {
        std::string buffer;
        const std::size_t parts = 1 + pick(3);
        for (std::size_t p = 0; p < parts; ++p) {
            std::string part = seeds[pick(seeds.size())];
            switch (pick(4)) {
                case 0: break;  // intact
                case 1: part[pick(part.size())] = alphabet[pick(alphabet.size())]; break;
                case 2: part.resize(pick(part.size())); break;
                default:
                    for (std::size_t i = pick(80); i > 0; --i) {
                        part.push_back(static_cast<char>(pick(256)));
                    }
                    break;
            }
            buffer += part;
        }
        ByteView rest = bytes(buffer);
        while (!rest.empty()) {
            const auto r = wtec::scan_frame(rest);
            REQUIRE(r.consumed <= rest.size());
            if (r.need_more()) break;
            REQUIRE(r.consumed > 0);
            if (r.complete()) {
                ++frames;
                REQUIRE(r.value.data.size() <= wtec::max_data_size);
                const auto command = wtec::decode_command(r.value);
                REQUIRE(command.consumed == 0);
                for (const auto& c : cases()) {
                    const auto reply = wtec::decode_reply(device, c.command, r.value);
                    REQUIRE(reply.consumed == 0);
                    if (reply.complete()) {
                        ++typed;
                        // Whatever decodes re-encodes to a frame that decodes the same
                        // ('$' replies come from whichever device answered).
                        const std::uint8_t from = c.letter == '$' ? r.value.address : device;
                        const auto again = wtec::decode_reply(
                            device, c.command, wtec::encode_reply(from, c.command, reply.value));
                        REQUIRE(again.complete());
                        CHECK(again.value == reply.value);
                    }
                }
                if (command.complete()) {
                    const auto again = wtec::decode_command(wtec::encode_command(r.value.address, command.value));
                    REQUIRE(again.complete());
                    CHECK(again.value == command.value);
                }
            }
            rest = rest.subspan(r.consumed);
        }
    }
    // The loop must have exercised the decoders, not only the scanner.
    CHECK(frames > 5000);
    CHECK(typed > 2000);
}
