#pragma once
// Protobuf wire format written by hand from field numbers (protobuf encoding guide:
// tag = field << 3 | wire type; varints little-endian base 128), for golden bytes that
// do not come from the library under test.
#include <cstdint>
#include <cstring>
#include <string>

namespace spb_test {

inline std::string varint(std::uint64_t value) {
    std::string out;
    while (value >= 0x80) {
        out += static_cast<char>((value & 0x7F) | 0x80);
        value >>= 7;
    }
    out += static_cast<char>(value);
    return out;
}
inline std::string tag(unsigned field, unsigned wire) { return varint(std::uint64_t{field} << 3 | wire); }
inline std::string field_varint(unsigned field, std::uint64_t value) { return tag(field, 0) + varint(value); }
inline std::string field_bytes(unsigned field, const std::string& bytes) {
    return tag(field, 2) + varint(bytes.size()) + bytes;
}
inline std::string field_float(unsigned field, float value) {
    std::uint32_t bits = 0;
    std::memcpy(&bits, &value, sizeof bits);
    std::string out = tag(field, 5);
    for (int i = 0; i < 4; ++i) out += static_cast<char>((bits >> (8 * i)) & 0xFF);
    return out;
}
inline std::string field_double(unsigned field, double value) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &value, sizeof bits);
    std::string out = tag(field, 1);
    for (int i = 0; i < 8; ++i) out += static_cast<char>((bits >> (8 * i)) & 0xFF);
    return out;
}

}  // namespace spb_test
