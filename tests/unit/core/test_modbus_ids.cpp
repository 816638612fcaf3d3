// core/modbus_ids.hpp: a unit ID, a bus address and a function byte are distinct
// types, made from a byte only on purpose and never from one another.
#include <doctest/doctest.h>

#include <cstdint>
#include <type_traits>

#include "core/modbus_ids.hpp"

namespace core = fieldbridge::core;

// The point of the types: none converts silently from a byte or into another.
static_assert(!std::is_convertible_v<std::uint8_t, core::UnitId>);
static_assert(!std::is_convertible_v<std::uint8_t, core::BusAddress>);
static_assert(!std::is_convertible_v<std::uint8_t, core::FunctionCode>);
static_assert(!std::is_convertible_v<core::UnitId, core::BusAddress>);
static_assert(!std::is_convertible_v<core::BusAddress, core::UnitId>);
static_assert(!std::is_convertible_v<core::UnitId, core::FunctionCode>);
static_assert(!std::is_convertible_v<core::UnitId, std::uint8_t>);
static_assert(sizeof(core::UnitId) == 1);

TEST_CASE("modbus ids: the byte goes in explicitly and comes back as value") {
    constexpr core::UnitId unit{17};
    CHECK(unit.value == 17);
    CHECK(core::UnitId{17} == unit);
    CHECK(core::UnitId{16} < unit);
    CHECK(core::BusAddress{} == core::BusAddress{0});
}

TEST_CASE("modbus ids: function codes are 1..127; 0 and the exception range are not") {
    CHECK(core::is_function_code(core::FunctionCode{0x01}));
    CHECK(core::is_function_code(core::FunctionCode{0x7F}));
    CHECK_FALSE(core::is_function_code(core::FunctionCode{0x00}));
    CHECK_FALSE(core::is_function_code(core::FunctionCode{0x80}));
    CHECK_FALSE(core::is_function_code(core::FunctionCode{0xFF}));
}
