#include "daemon/command_line.hpp"

#include <CLI/CLI.hpp>

#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "core/log_level.hpp"
#include "daemon/exit_codes.hpp"
#include "daemon/logging.hpp"

namespace fieldbridge::daemon {

namespace {

constexpr const char* usage_hint = "Run with --help for more information.";

[[nodiscard]] ExitCommand usage_error(std::ostream& err, const std::string& message) {
    err << message << '\n' << usage_hint << '\n';
    return ExitCommand{exit_usage};
}

}  // namespace

CommandLine::CommandLine(std::string version) : version_(std::move(version)) {}

void CommandLine::add_subcommand(Subcommand& subcommand) { subcommands_.push_back(&subcommand); }

Command CommandLine::parse(int argc, const char* const* argv, std::ostream& out, std::ostream& err) const {
    CLI::App app{"fieldbridge: RS-485 motion devices and Modbus TCP robot controllers, bridged to Modbus TCP "
                 "and MQTT.",
                 "fieldbridge"};
    app.set_version_flag("-V,--version", "fieldbridge " + version_);
    app.footer("Exit codes: 0 success, 1 runtime failure, 2 configuration error, 64 usage error.");

    std::string config_file;
    std::string check_file;
    std::string log_level_text;
    auto* config_option =
        app.add_option("-c,--config", config_file, "Run the gateway in the foreground with this configuration file")
            ->type_name("FILE");
    auto* check_option =
        app.add_option("--check-config", check_file, "Validate this configuration file, print every problem, and exit")
            ->type_name("FILE");
    std::vector<std::string> level_names;
    for (const auto& [name, level] : core::log_level_names) {
        level_names.emplace_back(name);
    }
    auto* level_option =
        app.add_option("-l,--log-level", log_level_text, "Log level, overriding gateway.log_level of the configuration")
            ->type_name("LEVEL")
            ->check(CLI::IsMember(level_names));
    config_option->excludes(check_option);
    level_option->excludes(check_option);

    std::vector<std::pair<CLI::App*, Subcommand*>> commands;
    for (auto* subcommand : subcommands_) {
        auto* command = app.add_subcommand(subcommand->name(), subcommand->description());
        subcommand->define(*command);
        commands.emplace_back(command, subcommand);
    }
    app.require_subcommand(0, 1);

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& error) {
        const int code = app.exit(error, out, err);
        return ExitCommand{code == static_cast<int>(CLI::ExitCodes::Success) ? exit_ok : exit_usage};
    }

    // Validated by IsMember above, so parse<LogLevel> cannot fail here.
    const auto log_level = log_level_text.empty() ? std::nullopt : core::parse<core::LogLevel>(log_level_text);
    for (const auto& [command, subcommand] : commands) {
        if (command->parsed()) {
            if (config_option->count() > 0 || check_option->count() > 0) {
                return usage_error(err, "--config and --check-config cannot be combined with the '" +
                                            subcommand->name() + "' subcommand");
            }
            return SubcommandCommand{subcommand, log_level};
        }
    }
    if (config_option->count() > 0) {
        return RunCommand{config_file, log_level};
    }
    if (check_option->count() > 0) {
        return CheckConfigCommand{check_file};
    }
    return usage_error(err, "fieldbridge: nothing to do; give --config FILE to run the gateway or --check-config FILE "
                            "to validate a configuration");
}

}  // namespace fieldbridge::daemon
