#pragma once
/// @file payload_codec.hpp
/// Sparkplug B payloads (payload.hpp) to protobuf bytes and back (Sparkplug 3.0,
/// "Payloads"; the schema is sparkplug_b.proto, the library protobuf-c). Pure functions:
/// no I/O, no state. docs/sparkplug.md, "Payloads", has the datatype rules.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "northbound/sparkplug/payload.hpp"

namespace fieldbridge::northbound::sparkplug {

/// What decode() accepts at most. Input beyond any of them is refused before (bytes,
/// nesting, counts, string lengths) or while (memory) it is unpacked, so memory and
/// stack stay bounded whatever arrives.
struct DecodeLimits {
    std::size_t max_bytes = 1024 * 1024;   ///< the whole payload
    std::size_t max_metrics = 10000;       ///< Payload.metrics
    std::size_t max_properties = 64;       ///< keys (and values) of one PropertySet
    std::size_t max_string_bytes = 4096;   ///< any one string or bytes field
    std::size_t max_depth = 8;             ///< nested messages, the Payload is depth 0
    std::size_t max_memory = 16 * 1024 * 1024;  ///< what unpacking may allocate in all
};

/// A decoded payload, or why there is none (one line for a log: what was wrong and
/// where; it may quote the input, so escape it before logging).
struct DecodeResult {
    std::optional<Payload> payload;
    std::string error;  ///< empty when payload holds a value
    [[nodiscard]] bool ok() const noexcept { return payload.has_value(); }
};

/// The payload as protobuf bytes. Integer values are written by datatype: Int8..UInt32
/// in int_value (Int8..Int32 negative as their 32-bit two's complement), Int64, UInt64
/// and DateTime in long_value; a monostate value sets is_null.
[[nodiscard]] std::string encode(const Payload& payload);

/// The payload in @p bytes, or a refusal naming the first thing wrong: malformed wire
/// format (truncated, wrong wire type, length past the end, groups), a limit passed,
/// a value field that does not fit its datatype, a datatype this model does not hold
/// (DataSet, Template, Bytes, arrays, ...), or property keys and values of different
/// counts.
[[nodiscard]] DecodeResult decode(std::string_view bytes, const DecodeLimits& limits = {});

/// The specification's name of @p type ("Int16", "Boolean", ...), "DataType <n>" else.
[[nodiscard]] std::string datatype_name(DataType type);

}  // namespace fieldbridge::northbound::sparkplug
