// Device definition files through the real loader (issue 25): --check-config names
// a broken definition's file:line:col, and a reload that meets one is rejected with
// the running configuration kept.

#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "config/config_loader.hpp"
#include "daemon/check_config.hpp"
#include "daemon/exit_codes.hpp"
#include "daemon_test_support.hpp"
#include "temp_dir.hpp"

using namespace fieldbridge::daemon;
using namespace fieldbridge::daemon::testing;
namespace config = fieldbridge::config;

namespace {

constexpr const char* gateway_yaml = "gateway: {id: t}\n"
                                     "definitions: [devices]\n"
                                     "lines:\n"
                                     "  - name: a\n"
                                     "    port: /dev/ttyS0\n"
                                     "    devices:\n"
                                     "      - {name: room, type: thermostat, address: 3, unit_id: 1}\n";

constexpr const char* good_definition = "name: thermostat\n"
                                        "points:\n"
                                        "  - {name: temperature, table: input, address: 0, type: float32}\n";

/// min > max on line 3, column 80.
constexpr const char* broken_definition =
    "name: thermostat\n"
    "points:\n"
    "  - {name: setpoint, table: holding, address: 0, writable: true, min: 30, max: 5}\n";

struct Files {
    fieldbridge::test::TempDir dir{"fb-definition-reload"};
    std::filesystem::path config = dir.path() / "gw.yaml";
    std::filesystem::path definition = dir.path() / "devices" / "thermostat.yaml";

    Files() {
        std::filesystem::create_directories(definition.parent_path());
        std::ofstream(config) << gateway_yaml;
        write_definition(good_definition);
    }
    void write_definition(const char* text) const { std::ofstream(definition, std::ios::trunc) << text; }
};

}  // namespace

TEST_CASE("--check-config reports a broken definition at its file:line:col") {
    const Files files;
    const ConfigLoader loader = [](const std::filesystem::path& file) { return config::load_config_file(file); };
    std::ostringstream out;
    std::ostringstream err;
    CHECK(check_config(files.config, loader, out, err) == exit_ok);
    CHECK(out.str().find("configuration is valid (1 line, 1 device") != std::string::npos);

    files.write_definition(broken_definition);
    out.str("");
    CHECK(check_config(files.config, loader, out, err) == exit_config_error);
    INFO(err.str());
    CHECK(err.str().find(files.definition.string() + ":3:80: points[0].max: max (5) is below min (30)") !=
          std::string::npos);
    CHECK(err.str().find(files.config.string() + ":7:28: lines[0].devices[0].type: the device definition " +
                         files.definition.string() + " has problems") != std::string::npos);
}

TEST_CASE("a reload meeting a broken definition is rejected; the running configuration stays") {
    const Files files;
    Harness h;
    h.initial = config::load_config_file(files.config);
    REQUIRE(h.initial->lines.at(0).devices.at(0).points.points.size() == 1);
    FakeComponent lines("lines", h.events);
    h.loader = [](const std::filesystem::path& file) { return config::load_config_file(file); };
    h.options.config_file = files.config;
    auto& daemon = h.create();
    daemon.add_component(lines);
    int readies = 0;
    h.manager.on_notify = [&](const std::string& message) {
        if (message.rfind("READY=1", 0) == 0) {
            ++readies;
            h.later([&, n = readies] {
                if (n == 1) {
                    files.write_definition(broken_definition);
                    daemon.request_reload();
                } else {
                    CHECK(daemon.config() == h.initial);
                    CHECK(lines.applied.empty());
                    daemon.request_stop("test");
                }
            });
        }
    };
    CHECK(h.run() == exit_ok);
    CHECK(readies == 2);
    INFO(h.log_text.str());
    CHECK(h.logged(files.definition.string() + ":3:80: points[0].max: max (5) is below min (30)"));
    CHECK(h.logged("configuration reload rejected"));
}
