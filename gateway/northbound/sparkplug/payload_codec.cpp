#include "northbound/sparkplug/payload_codec.hpp"

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <type_traits>
#include <vector>

#include "northbound/sparkplug/wire_check.hpp"
#include "sparkplug_b.pb-c.h"

namespace fieldbridge::northbound::sparkplug {
namespace {

using PbPayload = Org__Eclipse__Tahu__Protobuf__Payload;
using PbMetric = Org__Eclipse__Tahu__Protobuf__Payload__Metric;
using PbPropertySet = Org__Eclipse__Tahu__Protobuf__Payload__PropertySet;
using PbPropertyValue = Org__Eclipse__Tahu__Protobuf__Payload__PropertyValue;

// The value cases of Metric and PropertyValue: the same scalar fields under other
// numbers ("Payloads": Metric 10-15, PropertyValue 3-8).
template <typename Message>
struct Cases;
template <>
struct Cases<PbMetric> {
    using Case = Org__Eclipse__Tahu__Protobuf__Payload__Metric__ValueCase;
    static constexpr Case none = ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__METRIC__VALUE__NOT_SET;
    static constexpr Case int_value = ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__METRIC__VALUE_INT_VALUE;
    static constexpr Case long_value = ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__METRIC__VALUE_LONG_VALUE;
    static constexpr Case float_value = ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__METRIC__VALUE_FLOAT_VALUE;
    static constexpr Case double_value = ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__METRIC__VALUE_DOUBLE_VALUE;
    static constexpr Case boolean_value = ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__METRIC__VALUE_BOOLEAN_VALUE;
    static constexpr Case string_value = ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__METRIC__VALUE_STRING_VALUE;
};
template <>
struct Cases<PbPropertyValue> {
    using Case = Org__Eclipse__Tahu__Protobuf__Payload__PropertyValue__ValueCase;
    static constexpr Case none = ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__PROPERTY_VALUE__VALUE__NOT_SET;
    static constexpr Case int_value = ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__PROPERTY_VALUE__VALUE_INT_VALUE;
    static constexpr Case long_value = ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__PROPERTY_VALUE__VALUE_LONG_VALUE;
    static constexpr Case float_value = ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__PROPERTY_VALUE__VALUE_FLOAT_VALUE;
    static constexpr Case double_value = ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__PROPERTY_VALUE__VALUE_DOUBLE_VALUE;
    static constexpr Case boolean_value = ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__PROPERTY_VALUE__VALUE_BOOLEAN_VALUE;
    static constexpr Case string_value = ORG__ECLIPSE__TAHU__PROTOBUF__PAYLOAD__PROPERTY_VALUE__VALUE_STRING_VALUE;
};

bool in_int_value(DataType type) {
    switch (type) {
    case DataType::int8:
    case DataType::int16:
    case DataType::int32:
    case DataType::uint8:
    case DataType::uint16:
    case DataType::uint32:
        return true;
    default:
        return false;
    }
}

// Sets the value fields of @p out (a Metric or a PropertyValue) from @p value; the
// string stays owned by @p value.
template <typename Message>
void put_value(Message& out, const Value& value, std::optional<DataType> type) {
    using C = Cases<Message>;
    if (std::holds_alternative<std::monostate>(value)) {
        out.has_is_null = 1;
        out.is_null = 1;
    } else if (const auto* integer = std::get_if<std::uint64_t>(&value)) {
        if (type && in_int_value(*type)) {
            // Int8..Int32: the low 32 bits of the sign-extended pattern, i.e. the
            // value's 32-bit two's complement (-1 is 0xFFFFFFFF).
            out.value_case = C::int_value;
            out.int_value = static_cast<std::uint32_t>(*integer);
        } else {
            out.value_case = C::long_value;
            out.long_value = *integer;
        }
    } else if (const auto* f = std::get_if<float>(&value)) {
        out.value_case = C::float_value;
        out.float_value = *f;
    } else if (const auto* d = std::get_if<double>(&value)) {
        out.value_case = C::double_value;
        out.double_value = *d;
    } else if (const auto* b = std::get_if<bool>(&value)) {
        out.value_case = C::boolean_value;
        out.boolean_value = *b ? 1 : 0;
    } else {
        out.value_case = C::string_value;
        out.string_value = const_cast<char*>(std::get<std::string>(value).c_str());
    }
}

// The protobuf-c structures of one payload, pointing into the model (which outlives
// them) and into each other.
struct Tree {
    std::vector<PbMetric> metrics;
    std::vector<PbMetric*> metric_pointers;
    std::vector<PbPropertySet> sets;  // one per metric with properties
    std::vector<std::vector<char*>> keys;
    std::vector<std::vector<PbPropertyValue>> values;
    std::vector<std::vector<PbPropertyValue*>> value_pointers;
};

void put_properties(Tree& tree, std::size_t index, PbMetric& out, const std::vector<Property>& properties) {
    auto& keys = tree.keys[index];
    auto& values = tree.values[index];
    auto& pointers = tree.value_pointers[index];
    values.resize(properties.size());
    for (std::size_t i = 0; i < properties.size(); ++i) {
        const Property& property = properties[i];
        org__eclipse__tahu__protobuf__payload__property_value__init(&values[i]);
        values[i].has_type = 1;
        values[i].type = static_cast<std::uint32_t>(property.type);
        put_value(values[i], property.value, property.type);
        keys.push_back(const_cast<char*>(property.key.c_str()));
    }
    for (auto& value : values) pointers.push_back(&value);
    PbPropertySet& set = tree.sets[index];
    org__eclipse__tahu__protobuf__payload__property_set__init(&set);
    set.n_keys = keys.size();
    set.keys = keys.data();
    set.n_values = pointers.size();
    set.values = pointers.data();
    out.properties = &set;
}

// --- decoding ---

// protobuf-c's allocator with a budget: unpacking fails (returns NULL) rather than
// allocate past it.
struct Budget {
    std::size_t left;
    bool refused = false;
};
void* budget_alloc(void* data, std::size_t size) {
    auto* budget = static_cast<Budget*>(data);
    if (size > budget->left) {
        budget->refused = true;
        return nullptr;
    }
    budget->left -= size;
    return std::malloc(size);
}
void budget_free(void*, void* pointer) { std::free(pointer); }

struct Unpacked {
    ProtobufCAllocator allocator;
    void operator()(PbPayload* payload) const {
        org__eclipse__tahu__protobuf__payload__free_unpacked(payload, const_cast<ProtobufCAllocator*>(&allocator));
    }
};

bool known_datatype(std::uint32_t code) {
    return code <= static_cast<std::uint32_t>(DataType::text);
}

// An int_value read as @p type: UInt8..UInt32 within their range; Int8..Int32 as the
// 32-bit two's complement the encoder writes, or (Int8, Int16) the type's own width
// (0xFF for an Int8 -1), as some older encoders write it.
std::optional<std::uint64_t> read_int_value(std::uint32_t raw, DataType type) {
    const auto sign_extend = [](std::uint32_t bits, unsigned width) {
        const std::uint64_t sign = std::uint64_t{1} << (width - 1);
        const std::uint64_t value = bits & ((std::uint64_t{1} << width) - 1);
        return (value ^ sign) - sign;
    };
    const auto narrow = [&](unsigned width) -> std::optional<std::uint64_t> {
        const auto as_int32 = static_cast<std::int32_t>(raw);
        const std::int32_t low = -(std::int32_t{1} << (width - 1));
        const std::int32_t high = (std::int32_t{1} << (width - 1)) - 1;
        if (as_int32 >= low && as_int32 <= high) return static_cast<std::uint64_t>(static_cast<std::int64_t>(as_int32));
        if (raw < (std::uint32_t{1} << width)) return sign_extend(raw, width);
        return std::nullopt;
    };
    switch (type) {
    case DataType::int8:
        return narrow(8);
    case DataType::int16:
        return narrow(16);
    case DataType::int32:
        return static_cast<std::uint64_t>(static_cast<std::int64_t>(static_cast<std::int32_t>(raw)));
    case DataType::uint8:
        if (raw > 0xFFu) return std::nullopt;
        return raw;
    case DataType::uint16:
        if (raw > 0xFFFFu) return std::nullopt;
        return raw;
    default:
        return raw;
    }
}

// The value of @p in (a Metric or PropertyValue) under @p type (nullopt: none given);
// empty @p error when it fits.
template <typename Message>
Value read_value(const Message& in, std::optional<DataType> type, std::string& error) {
    using C = Cases<Message>;
    if (in.has_is_null && in.is_null) return std::monostate{};
    const auto wrong = [&](const char* field) {
        error = std::string(field) + " does not hold a " + datatype_name(*type);
        return Value{};
    };
    if (in.value_case == C::none) return std::monostate{};
    if (in.value_case == C::int_value) {
        if (!type) return std::uint64_t{in.int_value};
        if (!in_int_value(*type)) return wrong("int_value");
        const auto value = read_int_value(in.int_value, *type);
        if (!value) {
            error = "int_value " + std::to_string(in.int_value) + " is out of range for " + datatype_name(*type);
            return Value{};
        }
        return *value;
    }
    if (in.value_case == C::long_value) {
        if (type && *type != DataType::int64 && *type != DataType::uint64 && *type != DataType::datetime) {
            return wrong("long_value");
        }
        return std::uint64_t{in.long_value};
    }
    if (in.value_case == C::float_value) {
        if (type && *type != DataType::float32) return wrong("float_value");
        return in.float_value;
    }
    if (in.value_case == C::double_value) {
        if (type && *type != DataType::float64) return wrong("double_value");
        return in.double_value;
    }
    if (in.value_case == C::boolean_value) {
        if (type && *type != DataType::boolean) return wrong("boolean_value");
        return in.boolean_value != 0;
    }
    if (in.value_case == C::string_value) {
        if (type && *type != DataType::string && *type != DataType::text) return wrong("string_value");
        return std::string(in.string_value);
    }
    error = "value field " + std::to_string(static_cast<int>(in.value_case)) + " is not supported";
    return Value{};
}

std::string metric_label(const PbMetric& metric, std::size_t index) {
    std::string label = "metric " + std::to_string(index);
    if (metric.name != nullptr) label += " '" + std::string(metric.name) + "'";
    if (metric.has_alias) label += " (alias " + std::to_string(metric.alias) + ")";
    return label;
}

bool read_properties(const PbPropertySet& set, std::vector<Property>& out, std::string& error) {
    // tck-id-payloads-propertyset-keys-array-size, -values-array-size
    if (set.n_keys != set.n_values) {
        error = std::to_string(set.n_keys) + " property keys but " + std::to_string(set.n_values) + " values";
        return false;
    }
    for (std::size_t i = 0; i < set.n_keys; ++i) {
        const PbPropertyValue& in = *set.values[i];
        Property property;
        property.key = set.keys[i];
        std::optional<DataType> type;
        if (in.has_type) {
            if (!known_datatype(in.type)) {
                error = "property '" + property.key + "': type " + datatype_name(static_cast<DataType>(in.type)) +
                        " is not supported";
                return false;
            }
            type = static_cast<DataType>(in.type);
            property.type = *type;
        }
        property.value = read_value(in, type, error);
        if (!error.empty()) {
            error = "property '" + property.key + "': " + error;
            return false;
        }
        out.push_back(std::move(property));
    }
    return true;
}

std::optional<Metric> read_metric(const PbMetric& in, std::size_t index, std::string& error) {
    Metric metric;
    if (in.name != nullptr) metric.name = in.name;
    if (in.has_alias) metric.alias = in.alias;
    if (in.has_timestamp) metric.timestamp = in.timestamp;
    if (in.has_datatype) {
        if (!known_datatype(in.datatype)) {
            error = metric_label(in, index) + ": datatype " + datatype_name(static_cast<DataType>(in.datatype)) +
                    " is not supported";
            return std::nullopt;
        }
        metric.datatype = static_cast<DataType>(in.datatype);
    }
    metric.is_historical = in.has_is_historical && in.is_historical;
    metric.is_transient = in.has_is_transient && in.is_transient;
    metric.value = read_value(in, metric.datatype, error);
    if (error.empty() && in.properties != nullptr) read_properties(*in.properties, metric.properties, error);
    if (!error.empty()) {
        error = metric_label(in, index) + ": " + error;
        return std::nullopt;
    }
    return metric;
}

}  // namespace

std::string encode(const Payload& payload) {
    const std::size_t count = payload.metrics.size();
    Tree tree;
    tree.metrics.resize(count);
    tree.sets.resize(count);
    tree.keys.resize(count);
    tree.values.resize(count);
    tree.value_pointers.resize(count);
    for (std::size_t i = 0; i < count; ++i) {
        const Metric& metric = payload.metrics[i];
        PbMetric& out = tree.metrics[i];
        org__eclipse__tahu__protobuf__payload__metric__init(&out);
        if (metric.name) out.name = const_cast<char*>(metric.name->c_str());
        if (metric.alias) {
            out.has_alias = 1;
            out.alias = *metric.alias;
        }
        if (metric.timestamp) {
            out.has_timestamp = 1;
            out.timestamp = *metric.timestamp;
        }
        if (metric.datatype) {
            out.has_datatype = 1;
            out.datatype = static_cast<std::uint32_t>(*metric.datatype);
        }
        if (metric.is_historical) {
            out.has_is_historical = 1;
            out.is_historical = 1;
        }
        if (metric.is_transient) {
            out.has_is_transient = 1;
            out.is_transient = 1;
        }
        put_value(out, metric.value, metric.datatype);
        if (!metric.properties.empty()) put_properties(tree, i, out, metric.properties);
        tree.metric_pointers.push_back(&out);
    }
    PbPayload out;
    org__eclipse__tahu__protobuf__payload__init(&out);
    if (payload.timestamp) {
        out.has_timestamp = 1;
        out.timestamp = *payload.timestamp;
    }
    if (payload.seq) {
        out.has_seq = 1;
        out.seq = *payload.seq;
    }
    out.n_metrics = count;
    out.metrics = tree.metric_pointers.data();
    std::string bytes(org__eclipse__tahu__protobuf__payload__get_packed_size(&out), '\0');
    org__eclipse__tahu__protobuf__payload__pack(&out, reinterpret_cast<std::uint8_t*>(bytes.data()));
    return bytes;
}

DecodeResult decode(std::string_view bytes, const DecodeLimits& limits) {
    DecodeResult result;
    if (bytes.size() > limits.max_bytes) {
        result.error = std::to_string(bytes.size()) + " bytes, over the " + std::to_string(limits.max_bytes) +
                       " allowed";
        return result;
    }
    WireLimits wire;
    wire.max_depth = limits.max_depth;
    wire.max_string_bytes = limits.max_string_bytes;
    wire.max_repeated = limits.max_metrics;
    wire.counted_message = &org__eclipse__tahu__protobuf__payload__descriptor;
    wire.counted_field = 2;  // Payload.metrics
    wire.counted_max = limits.max_metrics;
    wire.narrow_message = &org__eclipse__tahu__protobuf__payload__property_set__descriptor;
    wire.narrow_max = limits.max_properties;
    result.error = check_wire(bytes, org__eclipse__tahu__protobuf__payload__descriptor, wire);
    if (!result.error.empty()) return result;

    Budget budget{limits.max_memory};
    Unpacked deleter{ProtobufCAllocator{budget_alloc, budget_free, &budget}};
    std::unique_ptr<PbPayload, Unpacked> in(
        org__eclipse__tahu__protobuf__payload__unpack(&deleter.allocator, bytes.size(),
                                                      reinterpret_cast<const std::uint8_t*>(bytes.data())),
        deleter);
    if (!in) {
        result.error = budget.refused ? "unpacking needs more than the " + std::to_string(limits.max_memory) +
                                            " bytes of memory allowed"
                                      : "protobuf-c refused the payload after the wire check passed";
        return result;
    }
    Payload payload;
    if (in->has_timestamp) payload.timestamp = in->timestamp;
    if (in->has_seq) payload.seq = in->seq;
    payload.metrics.reserve(in->n_metrics);
    for (std::size_t i = 0; i < in->n_metrics; ++i) {
        auto metric = read_metric(*in->metrics[i], i, result.error);
        if (!metric) return result;
        payload.metrics.push_back(std::move(*metric));
    }
    result.payload = std::move(payload);
    return result;
}

std::string datatype_name(DataType type) {
    // "Payloads", "Data Types": the enumeration's names.
    static constexpr const char* names[] = {
        "Unknown", "Int8", "Int16", "Int32", "Int64", "UInt8", "UInt16", "UInt32", "UInt64", "Float",
        "Double", "Boolean", "String", "DateTime", "Text", "UUID", "DataSet", "Bytes", "File", "Template",
        "PropertySet", "PropertySetList", "Int8Array", "Int16Array", "Int32Array", "Int64Array", "UInt8Array",
        "UInt16Array", "UInt32Array", "UInt64Array", "FloatArray", "DoubleArray", "BooleanArray", "StringArray",
        "DateTimeArray"};
    const auto code = static_cast<std::uint32_t>(type);
    if (code < std::size(names)) return names[code];
    return "DataType " + std::to_string(code);
}

}  // namespace fieldbridge::northbound::sparkplug
