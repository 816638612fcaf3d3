#include "northbound/sparkplug/wire_check.hpp"

#include <cstdint>
#include <map>
#include <optional>

namespace fieldbridge::northbound::sparkplug {
namespace {

// Protobuf wire types (protobuf encoding guide, "Message Structure").
constexpr unsigned wire_varint = 0;
constexpr unsigned wire_fixed64 = 1;
constexpr unsigned wire_length = 2;
constexpr unsigned wire_group_start = 3;
constexpr unsigned wire_group_end = 4;
constexpr unsigned wire_fixed32 = 5;

constexpr std::uint64_t max_field_number = (1u << 29) - 1;

// The wire type a field of @p type is written with (packed repeated scalars aside).
unsigned expected_wire_type(ProtobufCType type) {
    switch (type) {
    case PROTOBUF_C_TYPE_SFIXED64:
    case PROTOBUF_C_TYPE_FIXED64:
    case PROTOBUF_C_TYPE_DOUBLE:
        return wire_fixed64;
    case PROTOBUF_C_TYPE_SFIXED32:
    case PROTOBUF_C_TYPE_FIXED32:
    case PROTOBUF_C_TYPE_FLOAT:
        return wire_fixed32;
    case PROTOBUF_C_TYPE_STRING:
    case PROTOBUF_C_TYPE_BYTES:
    case PROTOBUF_C_TYPE_MESSAGE:
        return wire_length;
    default:
        return wire_varint;
    }
}

class Walker {
public:
    Walker(std::string_view bytes, const WireLimits& limits) : bytes_(bytes), limits_(limits) {}

    // Walks the message in [begin, end) of the input; false with error_ set on the
    // first problem.
    bool message(std::size_t begin, std::size_t end, const ProtobufCMessageDescriptor& descriptor,
                 std::size_t depth) {
        if (depth > limits_.max_depth) {
            return fail(begin, descriptor, nullptr,
                        "messages nested " + std::to_string(depth) + " deep, over the " +
                            std::to_string(limits_.max_depth) + " allowed");
        }
        std::map<unsigned, std::size_t> repeated;  // field number -> elements seen
        std::size_t at = begin;
        while (at < end) {
            const std::size_t tag_at = at;
            const auto tag = varint(at, end);
            if (!tag) return fail(tag_at, descriptor, nullptr, "truncated field tag");
            const std::uint64_t number = *tag >> 3;
            const auto wire = static_cast<unsigned>(*tag & 7u);
            if (number == 0 || number > max_field_number) {
                return fail(tag_at, descriptor, nullptr, "field number " + std::to_string(number) + " is not valid");
            }
            const ProtobufCFieldDescriptor* field =
                protobuf_c_message_descriptor_get_field(&descriptor, static_cast<unsigned>(number));
            std::size_t length = 0;
            switch (wire) {
            case wire_varint:
                if (!varint(at, end)) return fail(tag_at, descriptor, field, "truncated varint");
                break;
            case wire_fixed64:
            case wire_fixed32: {
                const std::size_t size = wire == wire_fixed64 ? 8 : 4;
                if (end - at < size) return fail(tag_at, descriptor, field, "truncated fixed-size value");
                at += size;
                break;
            }
            case wire_length: {
                const auto declared = varint(at, end);
                if (!declared) return fail(tag_at, descriptor, field, "truncated length");
                if (*declared > end - at) {
                    return fail(tag_at, descriptor, field,
                                "length " + std::to_string(*declared) + " runs past the end (" +
                                    std::to_string(end - at) + " bytes left)");
                }
                length = static_cast<std::size_t>(*declared);
                break;
            }
            case wire_group_start:
            case wire_group_end:
                return fail(tag_at, descriptor, field, "groups are not part of the Sparkplug B schema");
            default:
                return fail(tag_at, descriptor, field, "wire type " + std::to_string(wire) + " is not valid");
            }
            if (field != nullptr && !known_field(tag_at, at, length, wire, descriptor, *field, depth, repeated)) {
                return false;
            }
            at += length;
        }
        return true;
    }

    [[nodiscard]] const std::string& error() const { return error_; }

private:
    bool known_field(std::size_t tag_at, std::size_t at, std::size_t length, unsigned wire,
                     const ProtobufCMessageDescriptor& descriptor, const ProtobufCFieldDescriptor& field,
                     std::size_t depth, std::map<unsigned, std::size_t>& repeated) {
        const unsigned expected = expected_wire_type(field.type);
        const bool is_repeated = field.label == PROTOBUF_C_LABEL_REPEATED;
        // A repeated scalar may also come packed (one length-delimited run).
        const bool packed = is_repeated && wire == wire_length && expected != wire_length;
        if (wire != expected && !packed) {
            return fail(tag_at, descriptor, &field,
                        "wire type " + std::to_string(wire) + " where " + std::to_string(expected) + " belongs");
        }
        if (is_repeated) {
            const std::size_t count = ++repeated[field.id];
            std::size_t bound = limits_.max_repeated;
            if (&descriptor == limits_.counted_message && field.id == limits_.counted_field) {
                bound = limits_.counted_max;
            }
            if (&descriptor == limits_.narrow_message) bound = limits_.narrow_max;
            if (count > bound) {
                return fail(tag_at, descriptor, &field, "more than the " + std::to_string(bound) + " elements allowed");
            }
        }
        if ((field.type == PROTOBUF_C_TYPE_STRING || field.type == PROTOBUF_C_TYPE_BYTES) &&
            length > limits_.max_string_bytes) {
            return fail(tag_at, descriptor, &field,
                        "length " + std::to_string(length) + " is over the " +
                            std::to_string(limits_.max_string_bytes) + " allowed");
        }
        if (field.type == PROTOBUF_C_TYPE_MESSAGE) {
            const auto* child = static_cast<const ProtobufCMessageDescriptor*>(field.descriptor);
            return message(at, at + length, *child, depth + 1);
        }
        return true;
    }

    // The varint at @p at (advanced past it), nullopt when it is truncated or longer
    // than 10 bytes.
    std::optional<std::uint64_t> varint(std::size_t& at, std::size_t end) const {
        std::uint64_t value = 0;
        for (unsigned shift = 0; shift < 70 && at < end; shift += 7) {
            const auto byte = static_cast<unsigned char>(bytes_[at++]);
            value |= static_cast<std::uint64_t>(byte & 0x7Fu) << shift;
            if ((byte & 0x80u) == 0) return value;
        }
        return std::nullopt;
    }

    bool fail(std::size_t at, const ProtobufCMessageDescriptor& descriptor, const ProtobufCFieldDescriptor* field,
              const std::string& what) {
        // Names without the package: "Payload.Metric.name".
        std::string_view name = descriptor.name;
        const std::string_view package = descriptor.package_name;
        if (!package.empty() && name.size() > package.size() && name.starts_with(package)) {
            name.remove_prefix(package.size() + 1);
        }
        std::string where(name);
        if (field != nullptr) where += std::string(".") + field->name;
        error_ = "byte " + std::to_string(at) + ": " + where + ": " + what;
        return false;
    }

    std::string_view bytes_;
    const WireLimits& limits_;
    std::string error_;
};

}  // namespace

std::string check_wire(std::string_view bytes, const ProtobufCMessageDescriptor& message, const WireLimits& limits) {
    Walker walker(bytes, limits);
    if (walker.message(0, bytes.size(), message, 0)) return {};
    return walker.error();
}

}  // namespace fieldbridge::northbound::sparkplug
