// Writes payloads the gateway's encoder makes, for the tests' independent decoder
// (test_python_decoder.py): nbirth.bin (every datatype, properties), ddata.bin (aliases
// only), ndeath.bin (bdSeq only, no seq). Usage: fb_sparkplug_dump_payloads DIR
#include <cstdint>
#include <fstream>
#include <iostream>
#include <limits>
#include <string>

#include "northbound/sparkplug/payload_codec.hpp"

namespace {

namespace sp = fieldbridge::northbound::sparkplug;
constexpr std::uint64_t t0 = 1700000000000;

sp::Metric metric(std::string name, std::uint64_t alias, sp::DataType type, sp::Value value) {
    sp::Metric m;
    m.name = std::move(name);
    m.alias = alias;
    m.timestamp = t0;
    m.datatype = type;
    m.value = std::move(value);
    return m;
}

bool write(const std::string& path, const sp::Payload& payload) {
    std::ofstream out(path, std::ios::binary);
    const std::string bytes = sp::encode(payload);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return static_cast<bool>(out);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::cerr << "usage: fb_sparkplug_dump_payloads DIR\n";
        return 2;
    }
    const std::string dir = argv[1];
    using T = sp::DataType;
    const auto neg = [](std::int64_t v) { return static_cast<std::uint64_t>(v); };
    sp::Payload birth{t0, {}, 0};
    birth.metrics = {
        metric("bdSeq", 0, T::int64, std::uint64_t{7}),
        metric("i8", 1, T::int8, neg(-128)),
        metric("i16", 2, T::int16, neg(-300)),
        metric("i32", 3, T::int32, neg(std::numeric_limits<std::int32_t>::min())),
        metric("i64", 4, T::int64, neg(std::numeric_limits<std::int64_t>::min())),
        metric("u8", 5, T::uint8, std::uint64_t{255}),
        metric("u16", 6, T::uint16, std::uint64_t{65535}),
        metric("u32", 7, T::uint32, std::uint64_t{4294967295u}),
        metric("u64", 8, T::uint64, std::numeric_limits<std::uint64_t>::max()),
        metric("position_mm", 9, T::float32, 12.5f),
        metric("ratio", 10, T::float64, -0.125),
        metric("Node Control/Rebirth", 11, T::boolean, false),
        metric("name", 12, T::string, std::string("gripper \xC3\xA9")),
        metric("when", 13, T::datetime, std::uint64_t{t0}),
        metric("note", 14, T::text, std::string("text")),
        metric("unknown_yet", 15, T::float64, std::monostate{}),
    };
    birth.metrics[9].properties = {{"engUnit", T::string, std::string("mm")}, {"writable", T::boolean, true}};
    sp::Payload data{t0 + 1000, {}, 1};
    sp::Metric a;
    a.alias = 9;
    a.timestamp = t0 + 1000;
    a.value = 13.0f;
    sp::Metric b;
    b.alias = 2;
    b.timestamp = t0 + 1000;
    b.value = neg(-1);
    b.is_historical = true;
    data.metrics = {a, b};
    sp::Payload death{std::nullopt, {metric("bdSeq", 0, T::int64, std::uint64_t{7})}, std::nullopt};
    death.metrics[0].alias.reset();
    death.metrics[0].timestamp.reset();
    const bool ok = write(dir + "/nbirth.bin", birth) && write(dir + "/ddata.bin", data) &&
                    write(dir + "/ndeath.bin", death);
    if (!ok) std::cerr << "fb_sparkplug_dump_payloads: cannot write into " << dir << "\n";
    return ok ? 0 : 1;
}
