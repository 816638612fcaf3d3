#pragma once
/// @file payload.hpp
/// A Sparkplug B payload as the gateway handles it, before encoding and after decoding
/// (Sparkplug 3.0, "Payloads": the `Payload`, `Metric` and `PropertySet` messages of the
/// specification's protobuf schema). Only what an edge node sends or accepts is modelled:
/// no DataSet, Template or MetaData. The codec (payload_codec.hpp) turns it into bytes
/// and back; the session (session.hpp) decides what to publish. Plain values, no I/O.
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace fieldbridge::northbound::sparkplug {

/// Metric and property datatypes: the specification's `DataType` enumeration values.
enum class DataType : std::uint32_t {
    unknown = 0,
    int8 = 1,
    int16 = 2,
    int32 = 3,
    int64 = 4,
    uint8 = 5,
    uint16 = 6,
    uint32 = 7,
    uint64 = 8,
    float32 = 9,  ///< "Float"
    float64 = 10,  ///< "Double"
    boolean = 11,
    string = 12,
    datetime = 13,
    text = 14,
    property_set = 20,
};

/// A metric's or property's value. Integers of every width travel as their 64-bit
/// two's-complement pattern; the datatype says how to read them. monostate: null.
using Value = std::variant<std::monostate, std::uint64_t, float, double, bool, std::string>;

struct Property {
    std::string key;
    DataType type = DataType::unknown;
    Value value;
    bool operator==(const Property&) const = default;
};

struct Metric {
    std::optional<std::string> name;
    std::optional<std::uint64_t> alias;
    std::optional<std::uint64_t> timestamp;  ///< ms since the Unix epoch, UTC
    std::optional<DataType> datatype;
    bool is_historical = false;
    bool is_transient = false;
    Value value;  ///< monostate: is_null on the wire
    std::vector<Property> properties;
    bool operator==(const Metric&) const = default;
};

struct Payload {
    std::optional<std::uint64_t> timestamp;  ///< ms since the Unix epoch, UTC
    std::vector<Metric> metrics;
    std::optional<std::uint64_t> seq;  ///< absent in NDEATH
    bool operator==(const Payload&) const = default;
};

}  // namespace fieldbridge::northbound::sparkplug
