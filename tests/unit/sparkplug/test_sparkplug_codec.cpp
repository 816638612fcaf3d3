// Sparkplug B payload codec (gateway/northbound/sparkplug/payload_codec.*): golden bytes
// written from the schema's field numbers, round trips, datatype edges, malformed input.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "northbound/sparkplug/payload_codec.hpp"
#include "wire_builder.hpp"

namespace {

namespace sp = fieldbridge::northbound::sparkplug;
using namespace spb_test;

// Payload fields: timestamp 1, metrics 2, seq 3. Metric: name 1, alias 2, timestamp 3,
// datatype 4, is_historical 5, is_transient 6, is_null 7, properties 9, int_value 10,
// long_value 11, float_value 12, double_value 13, boolean_value 14, string_value 15.
// PropertySet: keys 1, values 2. PropertyValue: type 1, is_null 2, int_value 3,
// long_value 4, float 5, double 6, boolean 7, string 8.
constexpr std::uint64_t t0 = 1700000000000;

std::string bytes(std::initializer_list<unsigned> list) {
    std::string out;
    for (unsigned b : list) out += static_cast<char>(b);
    return out;
}

sp::Metric metric(std::string name, sp::DataType type, sp::Value value) {
    sp::Metric m;
    m.name = std::move(name);
    m.datatype = type;
    m.timestamp = t0;
    m.value = std::move(value);
    return m;
}

std::uint64_t pattern(std::int64_t value) { return static_cast<std::uint64_t>(value); }

}  // namespace

TEST_CASE("sparkplug codec: NDEATH with bdSeq only, byte for byte") {
    sp::Payload death;
    death.timestamp = t0;
    sp::Metric bd;
    bd.name = "bdSeq";
    bd.datatype = sp::DataType::int64;
    bd.value = std::uint64_t{3};
    death.metrics.push_back(bd);
    // Payload.timestamp (08, varint 1700000000000), Payload.metrics (12, 11 bytes):
    // name "bdSeq" (0A 05 ...), datatype Int64 (20 04), long_value 3 (58 03). No seq.
    const std::string golden = bytes({0x08, 0x80, 0xD0, 0x95, 0xFF, 0xBC, 0x31, 0x12, 0x0B, 0x0A, 0x05, 'b', 'd', 'S',
                                      'e', 'q', 0x20, 0x04, 0x58, 0x03});
    CHECK(sp::encode(death) == golden);
    const auto decoded = sp::decode(golden);
    REQUIRE(decoded.ok());
    CHECK(*decoded.payload == death);
    CHECK_FALSE(decoded.payload->seq.has_value());
}

TEST_CASE("sparkplug codec: NBIRTH with every datatype and an engUnit property, byte for byte") {
    sp::Payload birth;
    birth.timestamp = t0;
    birth.seq = 0;
    using T = sp::DataType;
    birth.metrics = {
        metric("i8", T::int8, pattern(-1)),
        metric("i16", T::int16, pattern(-300)),
        metric("i32", T::int32, pattern(std::numeric_limits<std::int32_t>::min())),
        metric("i64", T::int64, pattern(-2)),
        metric("u8", T::uint8, std::uint64_t{255}),
        metric("u16", T::uint16, std::uint64_t{65535}),
        metric("u32", T::uint32, std::uint64_t{4294967295u}),
        metric("u64", T::uint64, std::numeric_limits<std::uint64_t>::max()),
        metric("f", T::float32, 1.5f),
        metric("d", T::float64, -2.25),
        metric("b", T::boolean, true),
        metric("s", T::string, std::string("ok")),
        metric("dt", T::datetime, std::uint64_t{t0}),
        metric("tx", T::text, std::string("long text")),
        metric("n", T::float64, std::monostate{}),
    };
    birth.metrics[9].alias = 7;
    birth.metrics[9].properties.push_back(sp::Property{"engUnit", T::string, std::string("mm")});

    const auto head = [](const std::string& name, std::uint64_t type) {
        return field_bytes(1, name) + field_varint(3, t0) + field_varint(4, type);
    };
    std::string metrics;
    const auto add = [&](const std::string& body) { metrics += field_bytes(2, body); };
    add(head("i8", 1) + field_varint(10, 0xFFFFFFFFu));  // -1: 32-bit two's complement
    add(head("i16", 2) + field_varint(10, 0xFFFFFED4u));  // -300
    add(head("i32", 3) + field_varint(10, 0x80000000u));
    add(head("i64", 4) + field_varint(11, 0xFFFFFFFFFFFFFFFEu));
    add(head("u8", 5) + field_varint(10, 255));
    add(head("u16", 6) + field_varint(10, 65535));
    add(head("u32", 7) + field_varint(10, 4294967295u));
    add(head("u64", 8) + field_varint(11, 0xFFFFFFFFFFFFFFFFu));
    add(head("f", 9) + field_float(12, 1.5f));
    const std::string property_value = field_varint(1, 12) + field_bytes(8, "mm");
    const std::string property_set = field_bytes(1, "engUnit") + field_bytes(2, property_value);
    add(field_bytes(1, "d") + field_varint(2, 7) + field_varint(3, t0) + field_varint(4, 10) +
        field_bytes(9, property_set) + field_double(13, -2.25));
    add(head("b", 11) + field_varint(14, 1));
    add(head("s", 12) + field_bytes(15, "ok"));
    add(head("dt", 13) + field_varint(11, t0));
    add(head("tx", 14) + field_bytes(15, "long text"));
    add(head("n", 10) + field_varint(7, 1));  // is_null
    const std::string golden = field_varint(1, t0) + metrics + field_varint(3, 0);

    CHECK(sp::encode(birth) == golden);
    const auto decoded = sp::decode(golden);
    REQUIRE(decoded.ok());
    CHECK(*decoded.payload == birth);
}

TEST_CASE("sparkplug codec: DDATA with aliases only, byte for byte") {
    sp::Payload data;
    data.timestamp = t0;
    data.seq = 5;
    sp::Metric a;
    a.alias = 12;
    a.timestamp = t0;
    a.value = 3.5f;
    sp::Metric b;
    b.alias = 300;
    b.timestamp = t0;
    b.value = false;
    data.metrics = {a, b};
    const std::string golden = field_varint(1, t0) +
                               field_bytes(2, field_varint(2, 12) + field_varint(3, t0) + field_float(12, 3.5f)) +
                               field_bytes(2, field_varint(2, 300) + field_varint(3, t0) + field_varint(14, 0)) +
                               field_varint(3, 5);
    CHECK(sp::encode(data) == golden);
    const auto decoded = sp::decode(golden);
    REQUIRE(decoded.ok());
    CHECK(*decoded.payload == data);
}

TEST_CASE("sparkplug codec: every datatype's edge values survive a round trip") {
    using T = sp::DataType;
    struct Case {
        T type;
        sp::Value value;
    };
    const Case cases[] = {
        {T::int8, pattern(-128)},
        {T::int8, pattern(127)},
        {T::int16, pattern(-32768)},
        {T::int16, pattern(32767)},
        {T::int32, pattern(std::numeric_limits<std::int32_t>::min())},
        {T::int32, pattern(std::numeric_limits<std::int32_t>::max())},
        {T::int64, pattern(std::numeric_limits<std::int64_t>::min())},
        {T::int64, pattern(std::numeric_limits<std::int64_t>::max())},
        {T::uint8, std::uint64_t{0}},
        {T::uint8, std::uint64_t{255}},
        {T::uint16, std::uint64_t{65535}},
        {T::uint32, std::uint64_t{0xFFFFFFFFu}},
        {T::uint64, std::numeric_limits<std::uint64_t>::max()},
        {T::float32, std::numeric_limits<float>::lowest()},
        {T::float32, std::numeric_limits<float>::denorm_min()},
        {T::float32, std::numeric_limits<float>::infinity()},
        {T::float64, std::numeric_limits<double>::max()},
        {T::float64, -0.0},
        {T::boolean, false},
        {T::string, std::string()},
        {T::string, std::string("\xC3\xA9t\xC3\xA9 / \"q\"")},
        {T::datetime, std::uint64_t{0}},
        {T::text, std::string(4096, 'x')},
    };
    for (const Case& c : cases) {
        CAPTURE(sp::datatype_name(c.type));
        sp::Payload p;
        p.seq = 1;
        p.metrics.push_back(metric("m", c.type, c.value));
        const auto decoded = sp::decode(sp::encode(p));
        REQUIRE(decoded.ok());
        CHECK(*decoded.payload == p);
    }
    // NaN is not equal to itself: checked apart.
    sp::Payload p;
    p.metrics.push_back(metric("nan", T::float64, std::numeric_limits<double>::quiet_NaN()));
    const auto decoded = sp::decode(sp::encode(p));
    REQUIRE(decoded.ok());
    CHECK(std::isnan(std::get<double>(decoded.payload->metrics[0].value)));
}

TEST_CASE("sparkplug codec: Int8 and Int16 also read in their own width, ranges enforced") {
    const auto one = [](std::uint64_t type, std::uint64_t raw) {
        return sp::decode(field_bytes(2, field_bytes(1, "m") + field_varint(4, type) + field_varint(10, raw)));
    };
    auto r = one(1, 0xFF);  // an Int8 -1 written as one byte
    REQUIRE(r.ok());
    CHECK(std::get<std::uint64_t>(r.payload->metrics[0].value) == pattern(-1));
    r = one(2, 0x8000);
    REQUIRE(r.ok());
    CHECK(std::get<std::uint64_t>(r.payload->metrics[0].value) == pattern(-32768));
    r = one(1, 0x100);
    CHECK_FALSE(r.ok());
    CHECK(r.error.find("out of range for Int8") != std::string::npos);
    CHECK_FALSE(one(5, 256).ok());     // UInt8
    CHECK_FALSE(one(6, 65536).ok());   // UInt16
    CHECK(one(7, 0xFFFFFFFFu).ok());   // UInt32
}

TEST_CASE("sparkplug codec: a value field that does not fit the datatype is refused with the metric named") {
    const auto r = sp::decode(field_bytes(2, field_bytes(1, "speed") + field_varint(4, 9) + field_varint(14, 1)));
    REQUIRE_FALSE(r.ok());
    CHECK(r.error == "metric 0 'speed': boolean_value does not hold a Float");
    const auto dataset = sp::decode(field_bytes(2, field_bytes(1, "t") + field_varint(4, 16)));
    REQUIRE_FALSE(dataset.ok());
    CHECK(dataset.error == "metric 0 't': datatype DataSet is not supported");
    const std::string keys_only = field_bytes(1, "engUnit");
    const auto props = sp::decode(field_bytes(2, field_bytes(1, "p") + field_bytes(9, keys_only)));
    REQUIRE_FALSE(props.ok());
    CHECK(props.error == "metric 0 'p': 1 property keys but 0 values");
}

TEST_CASE("sparkplug codec: malformed input is refused with where and what") {
    const std::string good = sp::encode(sp::Payload{t0, {metric("position_mm", sp::DataType::float32, 1.0f)}, 0});
    SUBCASE("truncated inside a field, at every length") {
        // Bytes 0-6 are Payload.timestamp, then Payload.metrics up to the 2 bytes of seq;
        // a cut between two fields is a shorter payload, not a malformed one.
        REQUIRE(good.size() > 10);
        for (std::size_t n = 1; n < good.size() - 2; ++n) {
            if (n == 7) continue;
            CAPTURE(n);
            const auto r = sp::decode(std::string_view(good).substr(0, n));
            CHECK_FALSE(r.ok());
            CHECK_FALSE(r.error.empty());
        }
    }
    SUBCASE("wrong wire type") {
        const auto r = sp::decode(field_bytes(2, field_varint(1, 5)));  // name as a varint
        REQUIRE_FALSE(r.ok());
        CHECK(r.error == "byte 2: Payload.Metric.name: wire type 0 where 2 belongs");
        CHECK_FALSE(sp::decode(field_bytes(1, "x")).ok());  // timestamp as bytes
    }
    SUBCASE("a length past the end, and a huge one") {
        auto r = sp::decode(tag(2, 2) + varint(5) + "ab");
        REQUIRE_FALSE(r.ok());
        CHECK(r.error == "byte 0: Payload.metrics: length 5 runs past the end (2 bytes left)");
        r = sp::decode(tag(2, 2) + varint(0xFFFFFFFFFFFFull));
        REQUIRE_FALSE(r.ok());
        CHECK(r.error.find("runs past the end") != std::string::npos);
    }
    SUBCASE("a varint of more than 10 bytes, groups, field number 0") {
        CHECK_FALSE(sp::decode(tag(1, 0) + std::string(11, '\xFF')).ok());
        const auto group = sp::decode(tag(2, 3));
        REQUIRE_FALSE(group.ok());
        CHECK(group.error == "byte 0: Payload.metrics: groups are not part of the Sparkplug B schema");
        CHECK_FALSE(sp::decode(bytes({0x00, 0x00})).ok());
    }
    SUBCASE("nesting deeper than allowed, without recursing on it") {
        // Metric.properties (9) -> PropertySet.values (2) -> PropertyValue.propertyset_value
        // (9) -> PropertySet.values (2) -> ... 3000 levels.
        std::string nested;
        for (int i = 0; i < 3000; ++i) nested = (i % 2 == 0 ? field_bytes(9, nested) : field_bytes(2, nested));
        const auto r = sp::decode(field_bytes(2, field_bytes(9, nested)));
        REQUIRE_FALSE(r.ok());
        CHECK(r.error.find("nested 9 deep, over the 8 allowed") != std::string::npos);
    }
    SUBCASE("too many metrics, too many properties, strings over the bound, too many bytes") {
        std::string many;
        for (int i = 0; i < 11; ++i) many += field_bytes(2, field_varint(2, 1) + field_varint(11, 1));
        auto r = sp::decode(many, sp::DecodeLimits{.max_metrics = 10});
        REQUIRE_FALSE(r.ok());
        CHECK(r.error.find("Payload.metrics: more than the 10 elements allowed") != std::string::npos);
        std::string keys;
        for (int i = 0; i < 65; ++i) keys += field_bytes(1, "k");
        r = sp::decode(field_bytes(2, field_bytes(9, keys)));
        REQUIRE_FALSE(r.ok());
        CHECK(r.error.find("Payload.PropertySet.keys: more than the 64 elements allowed") != std::string::npos);
        r = sp::decode(field_bytes(2, field_bytes(1, std::string(4097, 'n'))));
        REQUIRE_FALSE(r.ok());
        CHECK(r.error == "byte 3: Payload.Metric.name: length 4097 is over the 4096 allowed");
        r = sp::decode(good, sp::DecodeLimits{.max_bytes = good.size() - 1});
        REQUIRE_FALSE(r.ok());
        CHECK(r.error.find("over the") != std::string::npos);
    }
    SUBCASE("memory: unpacking stops at its budget") {
        std::string many;
        for (int i = 0; i < 2000; ++i) many += field_bytes(2, field_varint(2, 1));
        const auto r = sp::decode(many, sp::DecodeLimits{.max_memory = 64 * 1024});
        REQUIRE_FALSE(r.ok());
        CHECK(r.error == "unpacking needs more than the 65536 bytes of memory allowed");
        CHECK(sp::decode(many).ok());
    }
    SUBCASE("unknown fields are skipped") {
        const auto r = sp::decode(good + field_bytes(4, "uuid") + field_varint(99, 1));
        REQUIRE(r.ok());
        CHECK(r.payload->metrics.size() == 1);
    }
}
