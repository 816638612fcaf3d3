// Modbus-RTU framing. Section numbers cite Modbus over Serial Line V1.02.
//
// Both framers share one resynchronising scan (scan_for_frame): every start offset
// of the receive buffer is judged as a candidate frame, and
//  - the first candidate that is complete with a good CRC wins; `consumed` runs from
//    the buffer start to its end, so garbage before it is dropped with it;
//  - otherwise, if some candidate may still complete, the bytes before the first such
//    candidate are reported malformed (drop them), or need_more if it starts at 0;
//  - otherwise nothing in the buffer can become a frame: all of it is malformed.
// A candidate is rejected only for reasons more bytes cannot change (address,
// function, CRC over the predicted length or, for a read reply whose byte count
// disagrees with the request, over the length that byte count gives), so dropping is
// always safe.
// The error reported for dropped bytes is the first one's, unless a later start got as
// far as the CRC (see weight()), so a corrupted reply behind noise counts as bad_crc.
//
// Local echo on 2-wire adapters is not detected here. The line worker knows how many
// bytes it sent and discards exactly that many echoed bytes before framing the
// reply. It must: for FC05/FC06 the echo is byte-identical to the correct reply (the
// WTEC-485 manual, 003 Modbus-RTU part, shows FC06 replies equal to the requests) and
// would be taken for it. Echoes of reads and multiple writes differ from the reply
// and would be skipped as garbage anyway.
#include "protocol/rtu_frame.hpp"

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <string>

#include "core/error.hpp"
#include "protocol/crc16.hpp"

namespace fieldbridge::protocol {
namespace {

/// Address + CRC around the PDU.
constexpr std::size_t rtu_overhead = 3;
/// Address, function code, CRC: the smallest ADU (2.5.1.1).
constexpr std::size_t min_rtu_adu_size = 4;

using FrameResult = DecodeResult<RtuFrame>;

enum class Verdict : std::uint8_t { valid, incomplete, rejected };

struct Candidate {
    Verdict verdict = Verdict::incomplete;
    std::size_t length = 0;                 ///< valid: ADU length
    DecodeError error = DecodeError::none;  ///< rejected: why
};

Candidate valid(std::size_t length) { return {Verdict::valid, length, DecodeError::none}; }
Candidate incomplete() { return {}; }
Candidate rejected(DecodeError why) { return {Verdict::rejected, 0, why}; }

/// The CRC over a whole ADU, its own CRC bytes included low byte first, is 0 (6.2.2).
bool crc_verifies(ByteView adu) noexcept { return crc16_modbus(adu) == 0; }

/// A candidate whose PDU length is known.
Candidate judge_known_length(ByteView at, std::size_t pdu_length) {
    const std::size_t adu = pdu_length + rtu_overhead;
    if (adu > max_rtu_adu_size) return rejected(DecodeError::oversize);
    if (at.size() < adu) return incomplete();
    return crc_verifies(at.first(adu)) ? valid(adu) : rejected(DecodeError::bad_crc);
}

/// A candidate for an opaque function code: the shortest prefix of at least 4 bytes
/// whose CRC verifies, within the 256-byte ADU limit. One running CRC tests them all.
Candidate judge_by_crc(ByteView at) {
    const std::size_t limit = std::min(at.size(), max_rtu_adu_size);
    std::uint16_t crc = crc16_modbus(at.first(std::min(limit, min_rtu_adu_size - 1)));
    for (std::size_t length = min_rtu_adu_size; length <= limit; ++length) {
        crc = crc16_modbus_update(crc, at.subspan(length - 1, 1));
        if (crc == 0) return valid(length);
    }
    return at.size() < max_rtu_adu_size ? incomplete() : rejected(DecodeError::bad_crc);
}

/// How telling a reason for dropped bytes is. The first dropped byte gives the reason,
/// unless a later start got as far as a CRC or byte-count check (it matched address
/// and function): noise followed by a corrupted reply is a bad CRC, not a wrong address.
/// A single data byte that happens to equal the address proves nothing.
int weight(DecodeError error) noexcept {
    switch (error) {
        case DecodeError::bad_crc: return 2;
        case DecodeError::unexpected_reply: return 1;
        default: return 0;
    }
}

template <typename Judge>
FrameResult scan_for_frame(ByteView rx, Judge judge) {
    if (rx.empty()) return FrameResult::more();
    std::optional<std::size_t> first_incomplete;
    DecodeError dropped_reason = DecodeError::none;
    for (std::size_t start = 0; start < rx.size(); ++start) {
        const ByteView at = rx.subspan(start);
        const Candidate candidate = judge(at);
        if (candidate.verdict == Verdict::valid) {
            const ByteView pdu = at.subspan(1, candidate.length - rtu_overhead);
            return FrameResult::ok(RtuFrame{at[0], Bytes(pdu.begin(), pdu.end())},
                                   start + candidate.length);
        }
        if (candidate.verdict == Verdict::incomplete) {
            if (!first_incomplete) first_incomplete = start;
        } else if (!first_incomplete &&
                   (start == 0 || weight(candidate.error) > weight(dropped_reason))) {
            dropped_reason = candidate.error;
        }
    }
    if (!first_incomplete) return FrameResult::bad(dropped_reason, rx.size());
    if (*first_incomplete == 0) return FrameResult::more();
    return FrameResult::bad(dropped_reason, *first_incomplete);
}

/// Function codes whose normal reply starts with a byte count (6.1-6.4, 6.17).
bool reply_has_byte_count(std::uint8_t function) noexcept {
    return function == fc::read_coils || function == fc::read_discrete_inputs ||
           function == fc::read_holding_registers || function == fc::read_input_registers ||
           function == fc::read_write_multiple_registers;
}

}  // namespace

Bytes encode_rtu(std::uint8_t address, ByteView pdu) {
    if (pdu.empty() || pdu.size() > max_pdu_size) {
        throw core::InvalidArgument("Modbus-RTU frame for address " + std::to_string(address) +
                                    ": PDU of " + std::to_string(pdu.size()) +
                                    " bytes is outside 1.." + std::to_string(max_pdu_size));
    }
    Bytes adu;
    adu.reserve(pdu.size() + rtu_overhead);
    adu.push_back(address);
    adu.insert(adu.end(), pdu.begin(), pdu.end());
    const std::uint16_t crc = crc16_modbus(adu);
    // 2.5.1.2: the CRC goes low-order byte first, unlike every other 16-bit field.
    adu.push_back(static_cast<std::uint8_t>(crc & 0xFF));
    adu.push_back(static_cast<std::uint8_t>(crc >> 8));
    return adu;
}

DecodeResult<RtuFrame> decode_rtu(ByteView adu) {
    const std::size_t size = adu.size();
    if (size < min_rtu_adu_size) return FrameResult::bad(DecodeError::bad_length, size);
    if (size > max_rtu_adu_size) return FrameResult::bad(DecodeError::oversize, size);
    if (!crc_verifies(adu)) return FrameResult::bad(DecodeError::bad_crc, size);
    const ByteView pdu = adu.subspan(1, size - rtu_overhead);
    return FrameResult::ok(RtuFrame{adu[0], Bytes(pdu.begin(), pdu.end())}, size);
}

DecodeResult<RtuFrame> frame_rtu_response(ByteView rx, std::uint8_t address, const Request& request) {
    // 2.1: a broadcast request is never answered (the EXCD203MB, seed 002, uses 0xFF
    // as its broadcast address, and 0xFF is a reserved address for every other
    // device). Anything received is not a reply.
    if (address == modbus_broadcast_address || address == excd_broadcast_address) {
        return rx.empty() ? FrameResult::more()
                          : FrameResult::bad(DecodeError::unexpected_reply, rx.size());
    }
    const std::uint8_t function = function_of(request);
    return scan_for_frame(rx, [&](ByteView at) {
        if (at[0] != address) return rejected(DecodeError::wrong_address);
        const ByteView pdu = at.subspan(1);
        const auto predicted = predict_response_pdu_length(pdu, request);
        if (!predicted) return judge_by_crc(at);
        if (predicted->status == DecodeStatus::need_more) return incomplete();
        if (predicted->status == DecodeStatus::malformed) return rejected(DecodeError::wrong_function);
        // A request whose reply could not fit an ADU (say 200 registers) has no reply.
        if (predicted->length + rtu_overhead > max_rtu_adu_size) {
            return rejected(DecodeError::oversize);
        }
        // Reads: a byte count other than the one the request implies cannot be the
        // answer. The device may still have sent a whole frame of that length (a
        // firmware that answers fewer registers than asked): framed by its own byte
        // count, as libmodbus frames, a good CRC makes it the device's reply, which
        // decode_response() then refuses (unexpected_reply), so the master answers at
        // once instead of waiting for a length that never comes.
        if (pdu[0] == function && reply_has_byte_count(function) && pdu.size() >= 2 &&
            pdu[1] + std::size_t{2} != predicted->length) {
            const Candidate own = judge_known_length(at, pdu[1] + std::size_t{2});
            return own.verdict == Verdict::rejected ? rejected(DecodeError::unexpected_reply) : own;
        }
        return judge_known_length(at, predicted->length);
    });
}

DecodeResult<RtuFrame> frame_rtu_request(ByteView rx) {
    return scan_for_frame(rx, [](ByteView at) {
        if (at.size() < 2) return incomplete();
        const std::uint8_t function = at[1];
        // 4.1: requests carry function codes 1..127; 0 and 128..255 cannot start one.
        if (function == 0 || (function & fc::exception_flag) != 0) {
            return rejected(DecodeError::bad_value);
        }
        const auto predicted = predict_request_pdu_length(at.subspan(1));
        if (!predicted) return judge_by_crc(at);
        if (predicted->status != DecodeStatus::complete) return incomplete();
        return judge_known_length(at, predicted->length);
    });
}

}  // namespace fieldbridge::protocol
