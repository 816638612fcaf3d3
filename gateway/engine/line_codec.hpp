#pragma once
/// @file line_codec.hpp
/// The two codecs a line carries, seen from the line master: the request bytes of a
/// transaction, and the scan of a receive buffer for its reply (Modbus-RTU framed by
/// the length predicted from the request; WTEC-485 ASCII by '>' ... CR LF). Pure.

#include <cstddef>

#include "engine/transaction.hpp"
#include "protocol/bytes.hpp"
#include "protocol/decode_result.hpp"

namespace fieldbridge::engine {

/// The request on the wire: RTU ADU (address + PDU + CRC) or the WTEC ASCII frame
/// with CR LF. Throws core::InvalidArgument when the codecs refuse the request.
[[nodiscard]] protocol::Bytes encode_wire_request(const Transaction& transaction);

struct ReplyScan {
    enum class Kind : std::uint8_t {
        need_more,  ///< nothing to act on yet
        reply,      ///< `reply` answers the request; drop `consumed` bytes
        dropped,    ///< drop `consumed` bytes (see `error`, `framed`) and scan again
    };
    Kind kind = Kind::need_more;
    Reply reply;
    std::size_t consumed = 0;
    /// reply: bytes skipped ahead of the reply frame (garbage, noise).
    std::size_t skipped = 0;
    /// dropped: why.
    protocol::DecodeError error = protocol::DecodeError::none;
    /// dropped: true when the bytes were a complete, checksum-valid frame that does not
    /// answer the request (another slave's ASCII reply, a mismatching echo); false for
    /// bytes that never became a frame (noise, bad CRC, a foreign RTU frame).
    bool framed = false;
};

/// Scans @p rx (bytes after the local echo) for the reply to @p transaction.
[[nodiscard]] ReplyScan scan_reply(protocol::ByteView rx, const Transaction& transaction);

/// Longest reply frame the codec of @p transaction allows (for the receive backstop).
[[nodiscard]] std::size_t max_reply_size(const Transaction& transaction) noexcept;

}  // namespace fieldbridge::engine
