// The built-in types' register maps come from their definitions (docs/devices.md,
// "Built-in types"): the compiled-in one by default, an operator's file when the
// configuration found one (ProfileOptions::registers).
#include <doctest/doctest.h>

#include <algorithm>
#include <vector>

#include "config/builtin_definitions.hpp"
#include "engine/profiles/excd_profile.hpp"
#include "engine/profiles/profile_factory.hpp"
#include "support.hpp"

namespace {

using namespace fbt;
using fp::ExceptionCode;
using fieldbridge::core::RegisterDef;

std::vector<RegisterDef> excd_rows() {
    const auto* definition = fieldbridge::config::builtin_definition(fe::DeviceType::excd203mb);
    REQUIRE(definition != nullptr);
    return definition->registers;
}

RegisterDef& row_named(std::vector<RegisterDef>& rows, std::string_view name) {
    const auto it = std::find_if(rows.begin(), rows.end(), [&](const RegisterDef& r) { return r.name == name; });
    REQUIRE(it != rows.end());
    return *it;
}

}  // namespace

TEST_CASE("excd203mb: an operator's narrower write range takes effect, the rest of the map stays") {
    const fe::RegisterImage image;
    fe::ProfileOptions options;
    options.registers = excd_rows();
    RegisterDef& abs = row_named(options.registers, "abs");
    abs.min = 0;
    abs.max = 100'000;
    abs.is_signed = false;
    const fe::ExcdProfile narrowed{options};
    const fe::ExcdProfile shipped{fe::ProfileOptions{}};
    // abs 100001 (0x000186A1) and -1: allowed by the shipped range, not by the site's.
    CHECK_FALSE(shipped.validate(write_multiple(0x0100, {0x0001, 0x86A1}), image));
    CHECK(narrowed.validate(write_multiple(0x0100, {0x0001, 0x86A1}), image) == ExceptionCode::illegal_data_value);
    CHECK(narrowed.validate(write_multiple(0x0100, {0xFFFF, 0xFFFF}), image) == ExceptionCode::illegal_data_value);
    CHECK_FALSE(narrowed.validate(write_multiple(0x0100, {0x0001, 0x86A0}), image));
    // Everything else as shipped: rel keeps its range, holes stay holes.
    CHECK_FALSE(narrowed.validate(write_multiple(0x0104, {0xFFFF, 0xFFFF}), image));
    CHECK(narrowed.validate(read_holding(0x003D, 1), image) == ExceptionCode::illegal_data_address);
}

TEST_CASE("excd203mb: an operator's protected register is refused with 0x01") {
    const fe::RegisterImage image;
    fe::ProfileOptions options;
    options.registers = excd_rows();
    row_named(options.registers, "cur").protect = true;
    const auto profile = fe::make_profile(fe::DeviceType::excd203mb, options);
    CHECK(profile->validate(write_single(0x0012, 0x14), image) == ExceptionCode::illegal_function);
    CHECK_FALSE(fe::make_profile(fe::DeviceType::excd203mb, {})->validate(write_single(0x0012, 0x14), image));
}

TEST_CASE("a map whose rows overlap is refused with ProfileError naming the type and the fix") {
    fe::ProfileOptions options;
    options.registers = excd_rows();
    options.registers.push_back(options.registers.front());
    try {
        (void)fe::ExcdProfile{options};
        FAIL("expected ProfileError");
    } catch (const fe::ProfileError& e) {
        CHECK(std::string(e.what()).find("excd203mb") != std::string::npos);
        CHECK(std::string(e.what()).find("registers:") != std::string::npos);
    }
}
