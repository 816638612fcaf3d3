#pragma once
/// @file wire_check.hpp
/// A walk over protobuf wire format guided by protobuf-c's message descriptors, done
/// before anything is unpacked: it refuses what the unpacker would take too much stack
/// or memory for (nesting, counts, long strings) and names what is malformed and where
/// (byte offset, message and field), which protobuf-c's unpacker does not say.
#include <cstddef>
#include <string>
#include <string_view>

#include <protobuf-c/protobuf-c.h>

namespace fieldbridge::northbound::sparkplug {

struct WireLimits {
    std::size_t max_depth = 8;
    std::size_t max_string_bytes = 4096;
    /// Elements of one repeated field in one message (Payload.metrics included).
    std::size_t max_repeated = 10000;
    /// A tighter bound for the repeated field @p counted_field of @p counted_message.
    const ProtobufCMessageDescriptor* counted_message = nullptr;
    unsigned counted_field = 0;
    std::size_t counted_max = 0;
    /// A bound for every repeated field of @p narrow_message (PropertySet keys/values).
    const ProtobufCMessageDescriptor* narrow_message = nullptr;
    std::size_t narrow_max = 0;
};

/// Empty when @p bytes is well-formed for @p message within @p limits; else the first
/// problem, e.g. "byte 12: Payload.Metric.name: length 70000 is over the 4096 allowed".
[[nodiscard]] std::string check_wire(std::string_view bytes, const ProtobufCMessageDescriptor& message,
                                     const WireLimits& limits);

}  // namespace fieldbridge::northbound::sparkplug
