#include "engine/line_codec.hpp"

#include <string>
#include <utility>

#include "protocol/rtu_frame.hpp"
#include "protocol/wtec_ascii_commands.hpp"
#include "protocol/wtec_ascii_frame.hpp"

namespace fieldbridge::engine {
namespace {

namespace wtec = protocol::wtec;
using protocol::DecodeError;

/// Address + CRC around an RTU PDU (Modbus over Serial Line V1.02, 2.5.1.1).
constexpr std::size_t rtu_overhead = 3;

ReplyScan need_more() { return {}; }

ReplyScan dropped(std::size_t consumed, DecodeError why, bool framed) {
    ReplyScan scan;
    scan.kind = ReplyScan::Kind::dropped;
    scan.consumed = consumed;
    scan.error = why;
    scan.framed = framed;
    return scan;
}

ReplyScan replied(Reply reply, std::size_t consumed, std::size_t frame_size) {
    ReplyScan scan;
    scan.kind = ReplyScan::Kind::reply;
    scan.reply = std::move(reply);
    scan.consumed = consumed;
    scan.skipped = consumed - frame_size;
    return scan;
}

ReplyScan scan_rtu(protocol::ByteView rx, std::uint8_t address, const protocol::Request& request) {
    auto framed = protocol::frame_rtu_response(rx, address, request);
    if (framed.need_more()) return need_more();
    if (framed.malformed()) return dropped(framed.consumed, framed.error, false);
    // The framer checked address, function, predicted length and CRC; the PDU decoder
    // checks what only the request tells: the quantity read, the echo of a write.
    auto decoded = protocol::decode_response(framed.value.pdu, request);
    if (!decoded.complete()) return dropped(framed.consumed, decoded.error, true);
    return replied(Reply{std::move(decoded.value)}, framed.consumed,
                   framed.value.pdu.size() + rtu_overhead);
}

ReplyScan scan_ascii(protocol::ByteView rx, std::uint8_t address, const wtec::Command& command) {
    // Seed 003, 1.2: a frame runs from '>' to CR LF; bytes before '>' are skipped.
    auto framed = wtec::scan_frame(rx);
    if (framed.need_more()) return need_more();
    if (framed.malformed()) return dropped(framed.consumed, framed.error, false);
    // decode_reply also turns the echo of an `E` request into NotExecuted (seed 003,
    // command E: "before homing it answers without moving, returning the command").
    auto decoded = wtec::decode_reply(address, command, framed.value);
    if (!decoded.complete()) return dropped(framed.consumed, decoded.error, true);
    return replied(Reply{std::move(decoded.value)}, framed.consumed,
                   wtec::frame_overhead + framed.value.data.size());
}

}  // namespace

protocol::Bytes encode_wire_request(const Transaction& transaction) {
    if (const auto* modbus = std::get_if<ModbusPayload>(&transaction.payload)) {
        return protocol::encode_rtu(transaction.address, protocol::encode_request(modbus->request));
    }
    const auto& ascii = std::get<AsciiPayload>(transaction.payload);
    const std::string text = wtec::encode_frame(wtec::encode_command(transaction.address, ascii.command));
    return protocol::Bytes(text.begin(), text.end());
}

ReplyScan scan_reply(protocol::ByteView rx, const Transaction& transaction) {
    if (const auto* modbus = std::get_if<ModbusPayload>(&transaction.payload)) {
        return scan_rtu(rx, transaction.address, modbus->request);
    }
    return scan_ascii(rx, transaction.address, std::get<AsciiPayload>(transaction.payload).command);
}

std::size_t max_reply_size(const Transaction& transaction) noexcept {
    return std::holds_alternative<ModbusPayload>(transaction.payload) ? protocol::max_rtu_adu_size
                                                                      : wtec::max_frame_size;
}

}  // namespace fieldbridge::engine
