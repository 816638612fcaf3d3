#pragma once
/// @file request_pdu.hpp
/// A Modbus request PDU as the Modbus TCP server received it, decoded once: the
/// access rules, the targets and, through them, the profiles' checks all read the
/// same typed request (protocol::Request). The bytes stay beside it for what only
/// bytes can serve: a function the codec does not know (passed through to an
/// upstream, or refused) and the byte-level scope of a malformed PDU (rules fail
/// closed on it, access_control.hpp).
#include "core/modbus_ids.hpp"
#include "protocol/bytes.hpp"
#include "protocol/decode_result.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::northbound {

struct RequestPdu {
    protocol::ByteView bytes;  ///< as received, function code first; valid during handle() only
    protocol::DecodeResult<protocol::Request> decoded;

    [[nodiscard]] static RequestPdu decode(protocol::ByteView pdu) { return RequestPdu{pdu, protocol::decode_request(pdu)}; }
    /// The first byte (0 for an empty PDU).
    [[nodiscard]] core::FunctionCode function() const noexcept { return protocol::pdu_function(bytes); }
};

}  // namespace fieldbridge::northbound
