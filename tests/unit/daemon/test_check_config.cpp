#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <unistd.h>

#include "config/config_loader.hpp"
#include "daemon/check_config.hpp"
#include "daemon/config_summary.hpp"
#include "daemon/exit_codes.hpp"
#include "temp_dir.hpp"

namespace daemon_ns = fieldbridge::daemon;
namespace config = fieldbridge::config;

namespace {

[[nodiscard]] std::shared_ptr<const config::Config> config_with(std::size_t lines, std::size_t devices_per_line,
                                                                std::size_t upstreams, bool mqtt) {
    auto built = std::make_shared<config::Config>();
    built->gateway.id = "test";
    built->lines.resize(lines);
    for (auto& line : built->lines) {
        line.devices.resize(devices_per_line);
    }
    built->upstreams.resize(upstreams);
    built->mqtt.enabled = mqtt;
    return built;
}

/// A file in a fresh temporary directory, removed at the end of the test.
class TempFile {
public:
    explicit TempFile(const std::string& text) {
        path_ = dir_.path() / "gateway.yaml";
        std::ofstream(path_) << text;
    }
    [[nodiscard]] const std::filesystem::path& path() const { return path_; }

private:
    fieldbridge::test::TempDir dir_{"fb-daemon"};
    std::filesystem::path path_;
};

}  // namespace

TEST_CASE("summaries count lines, devices and upstreams") {
    CHECK(daemon_ns::describe_inventory(*config_with(0, 0, 0, false)) == "0 lines, 0 devices");
    CHECK(daemon_ns::describe_inventory(*config_with(1, 1, 0, false)) == "1 line, 1 device");
    CHECK(daemon_ns::describe_inventory(*config_with(2, 2, 1, true)) == "2 lines, 4 devices, 1 upstream");
    CHECK(daemon_ns::describe_config(*config_with(2, 3, 2, true)) == "2 lines, 6 devices, 2 upstreams, MQTT enabled");
    CHECK(daemon_ns::describe_config(*config_with(1, 0, 0, false)) == "1 line, 0 devices, MQTT disabled");
}

TEST_CASE("the summary names the Sparkplug group and edge node when the section is present") {
    auto built = std::make_shared<config::Config>(*config_with(1, 0, 0, false));
    built->sparkplug = config::SparkplugConfig{};
    built->sparkplug->group_id = "plant1";
    built->sparkplug->edge_node_id = "gw-7";
    CHECK(daemon_ns::describe_config(*built) ==
          "1 line, 0 devices, MQTT disabled, Sparkplug B enabled (group plant1, edge node gw-7)");
}

TEST_CASE("a valid file: one line on stdout, exit 0") {
    std::ostringstream out;
    std::ostringstream err;
    const auto loader = [](const std::filesystem::path&) { return config_with(2, 2, 0, false); };
    CHECK(daemon_ns::check_config("gw.yaml", loader, out, err) == daemon_ns::exit_ok);
    CHECK(out.str() == "gw.yaml: configuration is valid (2 lines, 4 devices, MQTT disabled)\n");
    CHECK(err.str().empty());
}

TEST_CASE("an invalid file: every diagnostic on stderr, exit 2") {
    std::ostringstream out;
    std::ostringstream err;
    const auto loader = [](const std::filesystem::path&) -> std::shared_ptr<const config::Config> {
        throw config::ConfigError({config::Diagnostic{"gw.yaml", 3, 5, "gateway.id", "required key is missing"},
                                   config::Diagnostic{"gw.yaml", 9, 11, "lines[0].baud", "not a standard rate"}});
    };
    CHECK(daemon_ns::check_config("gw.yaml", loader, out, err) == daemon_ns::exit_config_error);
    CHECK(out.str().empty());
    CHECK(err.str() ==
          "gw.yaml:3:5: gateway.id: required key is missing\n"
          "gw.yaml:9:11: lines[0].baud: not a standard rate\n"
          "gw.yaml: 2 problems found; the configuration is not valid\n");
}

TEST_CASE("with the real loader: positions from the file, missing files") {
    const daemon_ns::ConfigLoader loader = [](const std::filesystem::path& file) {
        return config::load_config_file(file);
    };
    std::ostringstream out;
    std::ostringstream err;

    const TempFile valid("gateway:\n  id: t\nlines:\n  - name: a\n    port: /dev/ttyUSB9\n    devices:\n"
                         "      - {name: g1, type: hiwin-xeg, address: 1, unit_id: 1}\n");
    CHECK(daemon_ns::check_config(valid.path(), loader, out, err) == daemon_ns::exit_ok);
    CHECK(out.str() == valid.path().string() + ": configuration is valid (1 line, 1 device, MQTT disabled)\n");

    const TempFile invalid("gateway:\n  id: t\n  colour: blue\n");
    out.str("");
    err.str("");
    CHECK(daemon_ns::check_config(invalid.path(), loader, out, err) == daemon_ns::exit_config_error);
    CHECK(err.str().rfind(invalid.path().string() + ":3:3: gateway.colour: ", 0) == 0);

    out.str("");
    err.str("");
    CHECK(daemon_ns::check_config(valid.path().parent_path() / "absent.yaml", loader, out, err) ==
          daemon_ns::exit_config_error);
    CHECK(err.str().find("absent.yaml: cannot open") != std::string::npos);
    CHECK(out.str().empty());
}
