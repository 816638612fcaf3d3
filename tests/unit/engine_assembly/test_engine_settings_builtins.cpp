// From the configuration to the profile for a built-in type (docs/devices.md,
// "Built-in types"): an operator's copy of the type's definition file in the
// definitions: directories reaches the device's profile; without one, the
// compiled-in definition does.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "config/config_loader.hpp"
#include "engine/engine_settings.hpp"
#include "engine/profiles/profile_factory.hpp"
#include "temp_dir.hpp"

namespace {

namespace fc = fieldbridge::config;
namespace fe = fieldbridge::engine;
namespace fp = fieldbridge::protocol;

std::string shipped_excd() {
    std::ifstream in(std::filesystem::path(FIELDBRIDGE_SHIPPED_DEFINITIONS) / "excd203mb.yaml", std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// The profile of the one excd203mb device of a configuration in @p dir, whose
/// definitions: directory is @p dir/devices.
std::unique_ptr<fe::DeviceProfile> excd_profile(const std::filesystem::path& dir) {
    const auto file = dir / "gw.yaml";
    std::ofstream(file) << "gateway: {id: t}\n"
                           "definitions: [devices]\n"
                           "lines:\n"
                           "  - name: a\n"
                           "    port: /dev/ttyS0\n"
                           "    devices:\n"
                           "      - {name: axis, type: excd203mb, address: 3, unit_id: 1}\n";
    const auto config = fc::load_config_file(file);
    const fc::DeviceConfig& device = config->lines.at(0).devices.at(0);
    return fe::make_profile(device.type, fe::profile_options(device));
}

}  // namespace

TEST_CASE("engine settings: an operator's narrower range of a built-in type reaches the profile") {
    const fieldbridge::test::TempDir dir("fb-builtins");
    std::filesystem::create_directories(dir.path() / "devices");
    const fe::RegisterImage image;
    // abs 100001: inside the shipped range.
    const fp::Request abs_100001 = fp::WriteMultipleRegistersRequest{0x0100, {0x0001, 0x86A1}};
    CHECK_FALSE(excd_profile(dir.path())->validate(abs_100001, image));  // no file: compiled in

    std::string text = shipped_excd();
    const std::string row = "{name: abs, address: 0x0100, width: 2, access: write, motion: true, min: -8300000, "
                            "max: 8300000}";
    const auto at = text.find(row);
    REQUIRE(at != std::string::npos);
    text.replace(at, row.size(), "{name: abs, address: 0x0100, width: 2, access: write, motion: true, min: 0, "
                                 "max: 100000}");
    std::ofstream(dir.path() / "devices" / "excd203mb.yaml", std::ios::binary) << text;
    const auto narrowed = excd_profile(dir.path());
    CHECK(narrowed->validate(abs_100001, image) == fp::ExceptionCode::illegal_data_value);
    CHECK_FALSE(narrowed->validate(fp::WriteMultipleRegistersRequest{0x0100, {0x0001, 0x86A0}}, image));
}
