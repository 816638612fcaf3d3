// The WTEC-485 ASCII protocol (protocol/wtec_ascii_frame.hpp, wtec_ascii_commands.hpp):
// the frame scanner fed a receive buffer in chunks, as the line master scans for a
// reply (engine/line_codec.cpp); every frame it finds decoded as the reply to the
// command that was sent, and as a request (the simulator's side, decode_command).
// Input: one byte choosing the chunk boundaries, one byte choosing the command
// (23 letters), the device address, 4 bytes of command parameters, then the
// received bytes.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_input.hpp"
#include "protocol/wtec_ascii_commands.hpp"
#include "protocol/wtec_ascii_frame.hpp"

namespace {

namespace protocol = fieldbridge::protocol;
namespace wtec = protocol::wtec;

/// The command the gateway sent, chosen by @p which; parameters from @p p.
wtec::Command command_of(std::uint8_t which, std::span<const std::uint8_t> p) {
    const auto at = [&](std::size_t i) -> std::uint8_t { return i < p.size() ? p[i] : 0; };
    const auto u32 = static_cast<std::uint32_t>(at(0) << 24 | at(1) << 16 | at(2) << 8 | at(3));
    switch (which % 23) {
        case 0: return wtec::ReadVersion{};
        case 1: return wtec::ReadStations{};
        case 2: return wtec::SetMotorEnable{(at(0) & 1) != 0};
        case 3: return wtec::ReadHoming{};
        case 4: return wtec::WriteHoming{wtec::HomingParams{at(0), u32, u32, u32, at(1),
                                                            static_cast<std::uint8_t>(at(2) & 0xF), u32, u32}};
        case 5: return wtec::SetPeakCurrent{at(0)};
        case 6: return wtec::SetTarget{static_cast<std::int32_t>(u32)};
        case 7: return wtec::QueryGripState{};
        case 8: return wtec::GripperAction{static_cast<wtec::GripAction>(at(0) % 3 + 1)};
        case 9: return wtec::Home{};
        case 10: return wtec::QueryHoming{};
        case 11: return wtec::ReadRunning{};
        case 12: return wtec::SetAddress{static_cast<std::uint8_t>(at(0) % wtec::max_address + 1)};
        case 13: return wtec::ReadPid{};
        case 14: return wtec::WritePid{wtec::Pid{at(0), at(1), at(2)}};
        case 15: return wtec::ReadGripper{};
        case 16: return wtec::WriteGripper{wtec::GripperParams{u32, at(0), at(1), at(2),
                                                               static_cast<std::uint8_t>(at(3) & 0xF)}};
        case 17: return wtec::ReadDriver{};
        case 18: return wtec::WriteDriver{wtec::DriverParams{u32, u32, at(0), static_cast<std::uint8_t>(at(1) & 0xF),
                                                             at(2), at(3), static_cast<std::uint16_t>(u32), u32,
                                                             static_cast<std::uint8_t>(at(0) & 0xF)}};
        case 19: return wtec::SaveAll{};
        case 20: return wtec::ReadRelease{};
        case 21: return wtec::WriteRelease{wtec::ReleaseParams{at(0), at(1)}};
        default: return wtec::CalibrateEncoder{};
    }
}

/// A frame the scanner found: its text re-encodes to exactly the bytes it came from;
/// decoded as a reply or as a request, it survives a round trip through the encoder.
void check_frame(const wtec::AsciiFrame& frame, protocol::ByteView frame_bytes, std::uint8_t address,
                 const wtec::Command& command) {
    FB_FUZZ_CHECK(frame.data.size() <= wtec::max_data_size);
    const std::string text = wtec::encode_frame(frame);
    FB_FUZZ_CHECK(text.size() == frame_bytes.size() && std::equal(text.begin(), text.end(), frame_bytes.begin()));

    const auto reply = wtec::decode_reply(address, command, frame);
    if (reply.complete()) {
        // Encoded from the address that replied (for `$` any station, for `i` the new one).
        const auto reencoded = wtec::encode_reply(frame.address, command, reply.value);
        const auto again = wtec::decode_reply(address, command, reencoded);
        FB_FUZZ_CHECK(again.complete() && again.value == reply.value);
    } else {
        FB_FUZZ_CHECK(reply.malformed() && reply.error != protocol::DecodeError::none);
    }

    const auto request = wtec::decode_command(frame);
    if (request.complete()) {
        const auto again = wtec::decode_command(wtec::encode_command(frame.address, request.value));
        FB_FUZZ_CHECK(again.complete() && again.value == request.value);
    } else {
        FB_FUZZ_CHECK(request.malformed() && request.error != protocol::DecodeError::none);
    }
}

void drain(protocol::Bytes& buffer, std::uint8_t address, const wtec::Command& command) {
    while (!buffer.empty()) {
        const auto scanned = wtec::scan_frame(buffer);
        if (scanned.need_more()) {
            FB_FUZZ_CHECK(scanned.consumed == 0);
            return;
        }
        FB_FUZZ_CHECK(scanned.consumed > 0 && scanned.consumed <= buffer.size());
        if (scanned.malformed()) {
            FB_FUZZ_CHECK(scanned.error != protocol::DecodeError::none);
        } else {
            const std::size_t frame_size = wtec::frame_overhead + scanned.value.data.size();
            FB_FUZZ_CHECK(frame_size <= scanned.consumed && frame_size <= wtec::max_frame_size);
            check_frame(scanned.value, protocol::ByteView(buffer).subspan(scanned.consumed - frame_size, frame_size),
                        address, command);
        }
        buffer.erase(buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(scanned.consumed));
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    fieldbridge::fuzz::FuzzInput input(data, size);
    const std::uint8_t split = input.byte();
    const std::uint8_t which = input.byte();
    const std::uint8_t address = input.byte();
    const auto command = command_of(which, input.take(4));
    const auto rx = input.rest();

    protocol::Bytes buffer;
    for (const auto chunk : fieldbridge::fuzz::chunks(rx, split)) {
        buffer.insert(buffer.end(), chunk.begin(), chunk.end());
        drain(buffer, address, command);
    }
    return 0;
}
