// The point codec: every type × word order × byte order × scale, known patterns, limits.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "engine/points/point_codec.hpp"

namespace {

namespace fc = fieldbridge::core;
namespace pts = fieldbridge::engine::points;
using fc::ByteOrder;
using fc::PointType;
using fc::WordOrder;
using Regs = std::vector<std::uint16_t>;

fc::PointDef point(PointType type, WordOrder words = WordOrder::high_first, ByteOrder bytes = ByteOrder::big,
                   double scale = 1.0, double offset = 0.0) {
    fc::PointDef p;
    p.name = "p";
    p.type = type;
    p.word_order = words;
    p.byte_order = bytes;
    p.scale = scale;
    p.offset = offset;
    p.writable = true;
    return p;
}

Regs encoded(const fc::PointDef& p, const pts::PointValue& v) {
    const pts::Encoded e = pts::encode(p, v);
    INFO("encode error: " << e.error);
    REQUIRE(e.ok());
    CHECK(e.registers.size() == p.width());
    return e.registers;
}

std::string error_of(const fc::PointDef& p, const pts::PointValue& v) {
    const pts::Encoded e = pts::encode(p, v);
    CHECK(e.registers.empty());
    return e.error;
}

double as_double(const pts::PointValue& v) {
    if (const auto* i = std::get_if<std::int64_t>(&v)) return static_cast<double>(*i);
    return std::get<double>(v);
}

std::uint16_t swapped(std::uint16_t r) { return static_cast<std::uint16_t>(((r & 0xFFU) << 8) | (r >> 8)); }

}  // namespace

TEST_CASE("codec: known byte patterns") {
    CHECK(encoded(point(PointType::float32), 21.5) == Regs{0x41AC, 0x0000});
    CHECK(encoded(point(PointType::float32, WordOrder::low_first), 21.5) == Regs{0x0000, 0x41AC});
    CHECK(encoded(point(PointType::float32, WordOrder::high_first, ByteOrder::little), 21.5) == Regs{0xAC41, 0x0000});
    CHECK(encoded(point(PointType::int32), std::int64_t{-2}) == Regs{0xFFFF, 0xFFFE});
    CHECK(encoded(point(PointType::int32, WordOrder::low_first), std::int64_t{-2}) == Regs{0xFFFE, 0xFFFF});
    CHECK(encoded(point(PointType::int16), std::int64_t{-1}) == Regs{0xFFFF});
    CHECK(encoded(point(PointType::uint32), std::int64_t{0x12345678}) == Regs{0x1234, 0x5678});
    CHECK(encoded(point(PointType::uint32, WordOrder::high_first, ByteOrder::little), std::int64_t{0x12345678}) ==
          Regs{0x3412, 0x7856});
    CHECK(encoded(point(PointType::uint32, WordOrder::low_first), std::int64_t{0x12345678}) == Regs{0x5678, 0x1234});
    CHECK(encoded(point(PointType::uint32, WordOrder::low_first, ByteOrder::little), std::int64_t{0x12345678}) ==
          Regs{0x7856, 0x3412});
    CHECK(encoded(point(PointType::int64), std::int64_t{-2}) == Regs{0xFFFF, 0xFFFF, 0xFFFF, 0xFFFE});
    CHECK(encoded(point(PointType::int64, WordOrder::low_first), std::int64_t{0x0001000200030004}) ==
          Regs{0x0004, 0x0003, 0x0002, 0x0001});
    CHECK(encoded(point(PointType::float64), 1.0) == Regs{0x3FF0, 0, 0, 0});
    CHECK(encoded(point(PointType::float64, WordOrder::low_first, ByteOrder::little), 1.0) == Regs{0, 0, 0, 0xF03F});

    CHECK(std::get<double>(pts::decode(point(PointType::float32), Regs{0x41AC, 0x0000})) == 21.5);
    CHECK(std::get<std::int64_t>(pts::decode(point(PointType::int32), Regs{0xFFFF, 0xFFFE})) == -2);
    CHECK(std::get<std::int64_t>(pts::decode(point(PointType::int16), Regs{0x8000})) == -32768);
    CHECK(std::get<std::int64_t>(pts::decode(point(PointType::uint16), Regs{0x8000})) == 32768);
    CHECK(std::get<std::int64_t>(pts::decode(point(PointType::uint32), Regs{0xFFFF, 0xFFFF})) == 4294967295);
    CHECK(std::get<std::int64_t>(pts::decode(point(PointType::int64, WordOrder::low_first),
                                             Regs{0x0004, 0x0003, 0x0002, 0x0001})) == 0x0001000200030004);
    // uint64 above INT64_MAX: a double; its raw integer is not an int64.
    CHECK(std::get<double>(pts::decode(point(PointType::uint64), Regs{0xFFFF, 0xFFFF, 0xFFFF, 0xFFFF})) ==
          18446744073709551615.0);
    CHECK_FALSE(pts::raw_integer(point(PointType::uint64), Regs{0xFFFF, 0xFFFF, 0xFFFF, 0xFFFF}));
    CHECK(pts::raw_integer(point(PointType::int32), Regs{0xFFFF, 0xFFFE}) == -2);
    CHECK_FALSE(pts::raw_integer(point(PointType::float32), Regs{0x41AC, 0}));
}

TEST_CASE("codec: every type × word order × byte order × scale round-trips") {
    const std::vector<PointType> numeric{PointType::int16,  PointType::uint16, PointType::int32,
                                         PointType::uint32, PointType::int64,  PointType::uint64,
                                         PointType::float32, PointType::float64};
    struct Scaling {
        double scale;
        double offset;
    };
    const std::vector<Scaling> scalings{{1.0, 0.0}, {0.1, 0.0}, {0.5, -20.0}, {10.0, 3.0}};
    for (const PointType type : numeric) {
        for (const WordOrder words : {WordOrder::high_first, WordOrder::low_first}) {
            for (const ByteOrder bytes : {ByteOrder::big, ByteOrder::little}) {
                for (const Scaling s : scalings) {
                    const fc::PointDef p = point(type, words, bytes, s.scale, s.offset);
                    const fc::PointDef plain = point(type);
                    const bool is_signed = type == PointType::int16 || type == PointType::int32 ||
                                           type == PointType::int64 || type == PointType::float32 ||
                                           type == PointType::float64;
                    for (const double raw : {0.0, 1.0, 1234.0, is_signed ? -1234.0 : 4321.0}) {
                        const double eng = raw * s.scale + s.offset;
                        INFO(fc::to_string(type) << " words " << fc::to_string(words) << " bytes "
                                                 << fc::to_string(bytes) << " scale " << s.scale << " offset "
                                                 << s.offset << " eng " << eng);
                        const Regs regs = encoded(p, eng);
                        CHECK(as_double(pts::decode(p, regs)) == doctest::Approx(eng));
                        // The same value written plainly, then reordered by hand.
                        Regs expected = encoded(plain, raw);
                        if (words == WordOrder::low_first) std::reverse(expected.begin(), expected.end());
                        if (bytes == ByteOrder::little) {
                            for (auto& r : expected) r = swapped(r);
                        }
                        CHECK(regs == expected);
                    }
                }
            }
        }
    }
}

TEST_CASE("codec: the limits of each type") {
    CHECK(encoded(point(PointType::int16), std::int64_t{32767}) == Regs{0x7FFF});
    CHECK(encoded(point(PointType::int16), std::int64_t{-32768}) == Regs{0x8000});
    CHECK(error_of(point(PointType::int16), std::int64_t{32768}).find("range of int16") != std::string::npos);
    CHECK_FALSE(error_of(point(PointType::int16), std::int64_t{-32769}).empty());
    CHECK(encoded(point(PointType::uint16), std::int64_t{65535}) == Regs{0xFFFF});
    CHECK_FALSE(error_of(point(PointType::uint16), std::int64_t{-1}).empty());
    CHECK_FALSE(error_of(point(PointType::uint16), 65536.0).empty());
    CHECK(encoded(point(PointType::int32), std::int64_t{2147483647}) == Regs{0x7FFF, 0xFFFF});
    CHECK(encoded(point(PointType::int32), std::int64_t{-2147483648}) == Regs{0x8000, 0x0000});
    CHECK_FALSE(error_of(point(PointType::int32), std::int64_t{2147483648}).empty());
    CHECK(encoded(point(PointType::uint32), std::int64_t{4294967295}) == Regs{0xFFFF, 0xFFFF});
    CHECK_FALSE(error_of(point(PointType::uint32), std::int64_t{4294967296}).empty());
    CHECK_FALSE(error_of(point(PointType::uint32), std::int64_t{-1}).empty());
    const std::int64_t i64max = std::numeric_limits<std::int64_t>::max();
    const std::int64_t i64min = std::numeric_limits<std::int64_t>::min();
    CHECK(encoded(point(PointType::int64), i64max) == Regs{0x7FFF, 0xFFFF, 0xFFFF, 0xFFFF});
    CHECK(encoded(point(PointType::int64), i64min) == Regs{0x8000, 0, 0, 0});
    CHECK(std::get<std::int64_t>(pts::decode(point(PointType::int64), Regs{0x7FFF, 0xFFFF, 0xFFFF, 0xFFFF})) ==
          i64max);
    CHECK_FALSE(error_of(point(PointType::int64), 9.3e18).empty());
    CHECK_FALSE(error_of(point(PointType::uint64), std::int64_t{-1}).empty());
    CHECK(encoded(point(PointType::uint64), 1.8e19) == encoded(point(PointType::uint64), 18000000000000000000.0));
    CHECK(as_double(pts::decode(point(PointType::uint64), encoded(point(PointType::uint64), 1.8e19))) == 1.8e19);
    CHECK_FALSE(error_of(point(PointType::uint64), 1.9e19).empty());
    CHECK_FALSE(error_of(point(PointType::float32), 1e39).empty());
    CHECK(encoded(point(PointType::float32), 3.4e38).size() == 2);
    CHECK(encoded(point(PointType::float64), std::numeric_limits<double>::max()) == Regs{0x7FEF, 0xFFFF, 0xFFFF, 0xFFFF});
    // Scaled: the raw value is what must fit.
    const fc::PointDef tenths = point(PointType::int16, WordOrder::high_first, ByteOrder::big, 0.1);
    CHECK(encoded(tenths, 3276.7) == Regs{0x7FFF});
    CHECK(error_of(tenths, 3276.8).find("at scale 0.1") != std::string::npos);
    // (value - offset) / scale rounded to nearest.
    const fc::PointDef halves = point(PointType::int16, WordOrder::high_first, ByteOrder::big, 0.5, 1.0);
    CHECK(encoded(halves, 3.2) == Regs{4});    // 4.4 -> 4
    CHECK(encoded(halves, 3.3) == Regs{5});    // 4.6 -> 5
    CHECK(encoded(halves, -1.25) == Regs{0xFFFB});  // -4.5 -> -5
    CHECK(as_double(pts::decode(halves, Regs{5})) == 3.5);
}

TEST_CASE("codec: NaN and infinity are refused on write") {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    for (const PointType t : {PointType::float32, PointType::float64, PointType::int16, PointType::uint64}) {
        CHECK(error_of(point(t), nan).find("NaN") != std::string::npos);
        CHECK(error_of(point(t), inf).find("infinity") != std::string::npos);
        CHECK_FALSE(error_of(point(t), -inf).empty());
    }
    // A Modbus TCP write of a NaN's pattern is refused too; decode shows it as it is.
    CHECK(std::isnan(std::get<double>(pts::decode(point(PointType::float32), Regs{0x7FC0, 0x0000}))));
    CHECK_FALSE(pts::check_registers(point(PointType::float32), Regs{0x7FC0, 0x0000}).empty());
    CHECK_FALSE(pts::check_registers(point(PointType::float32), Regs{0x7F80, 0x0000}).empty());
    CHECK(pts::check_registers(point(PointType::float32), Regs{0x41AC, 0x0000}).empty());
}

TEST_CASE("codec: min and max in engineering units, with a clear text") {
    fc::PointDef p = point(PointType::int16, WordOrder::high_first, ByteOrder::big, 0.1);
    p.min = 5.0;
    p.max = 30.0;
    p.unit = "°C";
    CHECK(error_of(p, 30.5) == "30.5 °C is above the maximum 30 °C");
    CHECK(error_of(p, std::int64_t{4}) == "4 °C is below the minimum 5 °C");
    CHECK(encoded(p, std::int64_t{30}) == Regs{300});
    CHECK(encoded(p, 5.0) == Regs{50});
    CHECK(pts::check_registers(p, Regs{301}) == "30.1 °C is above the maximum 30 °C");
    CHECK(pts::check_registers(p, Regs{300}).empty());
    CHECK_FALSE(pts::check_registers(p, Regs{0xFFFF}).empty());  // -0.1
}

TEST_CASE("codec: wrong value types are refused") {
    CHECK(error_of(point(PointType::int16), std::string{"7"}) == "it takes a number, not a string");
    CHECK(error_of(point(PointType::float32), true) == "it takes a number, not a boolean");
    CHECK(error_of(point(PointType::boolean), std::int64_t{1}) == "it takes true or false, not a number");
    fc::PointDef s = point(PointType::string);
    s.count = 2;
    CHECK(error_of(s, 1.5) == "it takes a string, not a number");
}

TEST_CASE("codec: enum labels and codes") {
    fc::PointDef p = point(PointType::uint16);
    p.labels = {{0, "off"}, {1, "heat"}, {2, "cool"}};
    CHECK(encoded(p, std::string{"heat"}) == Regs{1});
    CHECK(encoded(p, std::int64_t{2}) == Regs{2});
    CHECK(encoded(p, 2.0) == Regs{2});
    CHECK(error_of(p, std::string{"dry"}) == "'dry' is not one of its labels: off (0), heat (1), cool (2)");
    CHECK(error_of(p, std::int64_t{5}).find("code 5 has no label") == 0);
    CHECK_FALSE(error_of(p, 1.5).empty());
    CHECK_FALSE(error_of(p, true).empty());
    CHECK(std::get<std::int64_t>(pts::decode(p, Regs{2})) == 2);
    CHECK(pts::label_of(p, 2) == "cool");
    CHECK(pts::label_of(p, 9).empty());
    CHECK(pts::check_registers(p, Regs{1}).empty());
    CHECK(pts::check_registers(p, Regs{7}).find("code 7 has no label") == 0);
    // An enum ignores scale: the code is the raw value.
    p.scale = 0.1;
    CHECK(std::get<std::int64_t>(pts::decode(p, Regs{1})) == 1);
    CHECK(encoded(p, std::string{"cool"}) == Regs{2});
    // A signed enum.
    fc::PointDef s = point(PointType::int16);
    s.labels = {{-1, "fault"}, {0, "ok"}};
    CHECK(encoded(s, std::string{"fault"}) == Regs{0xFFFF});
    CHECK(std::get<std::int64_t>(pts::decode(s, Regs{0xFFFF})) == -1);
}

TEST_CASE("codec: bit points, coils and bool registers") {
    fc::PointDef b = point(PointType::boolean);
    b.bit = 3;
    CHECK(std::get<bool>(pts::decode(b, Regs{0x0008})));
    CHECK_FALSE(std::get<bool>(pts::decode(b, Regs{0xFFF7})));
    CHECK(pts::raw_integer(b, Regs{0x0008}) == 1);
    CHECK(pts::raw_integer(b, Regs{0x0007}) == 0);
    CHECK(encoded(b, true) == Regs{0x0008});
    CHECK(encoded(b, false) == Regs{0x0000});
    b.bit = 15;
    CHECK(std::get<bool>(pts::decode(b, Regs{0x8000})));
    CHECK(encoded(b, true) == Regs{0x8000});

    fc::PointDef coil = point(PointType::boolean);
    coil.table = fc::RegisterTable::coils;
    CHECK(std::get<bool>(pts::decode(coil, Regs{1})));
    CHECK_FALSE(std::get<bool>(pts::decode(coil, Regs{0})));
    CHECK(encoded(coil, true) == Regs{1});

    const fc::PointDef whole = point(PointType::boolean);  // a register, non-zero is true
    CHECK(std::get<bool>(pts::decode(whole, Regs{0x0100})));
    CHECK(encoded(whole, true) == Regs{1});
}

TEST_CASE("codec: invert makes a bool true while its bit (coil, register) is 0, both ways") {
    fc::PointDef busy = point(PointType::boolean);
    busy.bit = 0;
    busy.invert = true;
    CHECK(std::get<bool>(pts::decode(busy, Regs{0x0000})));
    CHECK_FALSE(std::get<bool>(pts::decode(busy, Regs{0x0001})));
    CHECK(std::get<bool>(pts::decode(busy, Regs{0x0002})));  // only bit 0 counts
    CHECK(pts::raw_integer(busy, Regs{0x0000}) == 1);
    CHECK(encoded(busy, true) == Regs{0x0000});
    CHECK(encoded(busy, false) == Regs{0x0001});
    busy.bit = 12;
    CHECK(encoded(busy, false) == Regs{0x1000});

    fc::PointDef coil = point(PointType::boolean);
    coil.table = fc::RegisterTable::coils;
    coil.invert = true;
    CHECK(std::get<bool>(pts::decode(coil, Regs{0})));
    CHECK_FALSE(std::get<bool>(pts::decode(coil, Regs{1})));
    CHECK(encoded(coil, true) == Regs{0});
    CHECK(encoded(coil, false) == Regs{1});
}

TEST_CASE("codec: format hex shows the registers in the point's orders, four digits a register") {
    fc::PointDef v = point(PointType::uint32);
    v.format = fc::PointFormat::hex;
    CHECK(std::get<std::string>(pts::decode(v, Regs{0x0000, 0x0078})) == "0x00000078");
    CHECK(std::get<std::string>(pts::decode(v, Regs{0xDEAD, 0xBEEF})) == "0xDEADBEEF");
    v.word_order = WordOrder::low_first;
    CHECK(std::get<std::string>(pts::decode(v, Regs{0xBEEF, 0xDEAD})) == "0xDEADBEEF");
    v.byte_order = ByteOrder::little;
    CHECK(std::get<std::string>(pts::decode(v, Regs{0xEFBE, 0xADDE})) == "0xDEADBEEF");
    CHECK(pts::raw_integer(v, Regs{0xEFBE, 0xADDE}) == 0xDEADBEEF);

    fc::PointDef s16 = point(PointType::int16);
    s16.format = fc::PointFormat::hex;
    CHECK(std::get<std::string>(pts::decode(s16, Regs{0xFFFE})) == "0xFFFE");  // the bits, not -2
    fc::PointDef u64 = point(PointType::uint64);
    u64.format = fc::PointFormat::hex;
    CHECK(std::get<std::string>(pts::decode(u64, Regs{0x0123, 0x4567, 0x89AB, 0xCDEF})) == "0x0123456789ABCDEF");
}

TEST_CASE("codec: a scale of 1/n gives the decimal an operator expects") {
    // 35 × 0.01 is 0.35000000000000003 in binary floating point; 35 / 100 is 0.35.
    for (const double scale : {0.1, 0.01, 0.001}) {
        const fc::PointDef p = point(PointType::uint16, WordOrder::high_first, ByteOrder::big, scale, 0.0);
        for (std::uint32_t raw = 0; raw <= 0xFFFF; ++raw) {
            const double expected = static_cast<double>(raw) / std::round(1.0 / scale);
            if (std::get<double>(pts::decode(p, Regs{static_cast<std::uint16_t>(raw)})) != expected) {
                FAIL("scale " << scale << " raw " << raw);
            }
        }
        // And a write of that decimal is the raw value again.
        for (const std::uint16_t raw : {std::uint16_t{35}, std::uint16_t{884}, std::uint16_t{65535}}) {
            CHECK(encoded(p, static_cast<double>(raw) / std::round(1.0 / scale)) == Regs{raw});
        }
    }
    // Other scales multiply, as before.
    const fc::PointDef half = point(PointType::int16, WordOrder::high_first, ByteOrder::big, 0.5, -20.0);
    CHECK(std::get<double>(pts::decode(half, Regs{41})) == 0.5);
}

TEST_CASE("codec: a format template shows the point's registers") {
    fc::PointDef v = point(PointType::uint16);
    v.format = fc::PointFormat::text;
    v.count = 4;
    v.format_text = "V{0}.{1}.{2}.{3}";
    CHECK(v.width() == 4);
    CHECK(std::get<std::string>(pts::decode(v, Regs{3, 0, 1, 884})) == "V3.0.1.884");
    v.format_text = "{1:hex}-{0} {{raw}}";
    CHECK(std::get<std::string>(pts::decode(v, Regs{65535, 0x0A20, 0, 0})) == "0x0A20-65535 {raw}");
    v.type = PointType::int16;
    CHECK(std::get<std::string>(pts::decode(v, Regs{65535, 0x0A20, 0, 0})) == "0x0A20--1 {raw}");
}

TEST_CASE("codec: enum_other shows the code it stands for as {value} or {value:hex}") {
    fc::PointDef m = point(PointType::uint16);
    m.labels = {{0x0A10, "XEG-16"}};
    CHECK(pts::enum_text(m, 0x0A10) == "XEG-16");
    CHECK(pts::enum_text(m, 0x0A99).empty());  // no enum_other: the caller shows the code
    m.enum_other = "unknown ({value:hex})";
    CHECK(pts::enum_text(m, 0x0A99) == "unknown (0x0A99)");
    m.enum_other = "code {value}";
    CHECK(pts::enum_text(m, 0x0A99) == "code 2713");
    m.enum_other = "unknown";
    CHECK(pts::enum_text(m, 7) == "unknown");
    fc::PointDef wide = point(PointType::uint32);
    wide.labels = {{1, "one"}};
    wide.enum_other = "{value:hex}";
    CHECK(pts::enum_text(wide, 0x10000) == "0x00010000");
}

TEST_CASE("codec: strings, two ASCII characters a register, NULs trimmed") {
    fc::PointDef s = point(PointType::string);
    s.count = 3;
    CHECK(s.width() == 3);
    CHECK(encoded(s, std::string{"ABCD"}) == Regs{0x4142, 0x4344, 0x0000});
    CHECK(encoded(s, std::string{"ABC"}) == Regs{0x4142, 0x4300, 0x0000});
    CHECK(encoded(s, std::string{}) == Regs{0, 0, 0});
    CHECK(std::get<std::string>(pts::decode(s, Regs{0x4142, 0x4344, 0x0000})) == "ABCD");
    CHECK(std::get<std::string>(pts::decode(s, Regs{0x4142, 0x4300, 0x0000})) == "ABC");
    CHECK(std::get<std::string>(pts::decode(s, Regs{0x4142, 0x4344, 0x4546})) == "ABCDEF");
    // A NUL inside is kept (only trailing ones go); non-printable bytes are the caller's to escape.
    CHECK(std::get<std::string>(pts::decode(s, Regs{0x4100, 0x0142, 0x0000})) == std::string("A\0\x01" "B", 4));
    CHECK(error_of(s, std::string{"ABCDEFG"}) == "7 characters do not fit in 3 registers (at most 6)");
    CHECK_FALSE(error_of(s, std::string{"caf\xC3\xA9"}).empty());
    s.byte_order = ByteOrder::little;
    CHECK(encoded(s, std::string{"ABC"}) == Regs{0x4241, 0x0043, 0x0000});
    CHECK(std::get<std::string>(pts::decode(s, Regs{0x4241, 0x0043, 0x0000})) == "ABC");
}

TEST_CASE("codec: to_text for operators") {
    CHECK(pts::to_text(true) == "true");
    CHECK(pts::to_text(std::int64_t{-2}) == "-2");
    CHECK(pts::to_text(21.5) == "21.5");
    CHECK(pts::to_text(std::string{"on"}) == "\"on\"");
}
