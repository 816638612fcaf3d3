#pragma once
/// @file command_line.hpp
/// The `fieldbridge` command line (CLI11):
///
///     fieldbridge --config FILE [--log-level LEVEL]   run in the foreground
///     fieldbridge --check-config FILE                 validate FILE and exit
///     fieldbridge --version | --help
///     fieldbridge <subcommand> ...                    tools added by other layers
///
/// Tools such as `scan --port DEV [--baud N]` plug in as Subcommand objects
/// registered before parse(); the daemon's own modes stay top-level options.

#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "config/config.hpp"

namespace CLI {
class App;
}

namespace fieldbridge::daemon {

/// A tool run instead of the daemon (e.g. a line scan). It defines its own
/// options on its CLI11 subcommand and binds them to its members; run() is
/// called after a successful parse.
class Subcommand {
public:
    Subcommand() = default;
    Subcommand(const Subcommand&) = delete;
    Subcommand& operator=(const Subcommand&) = delete;
    Subcommand(Subcommand&&) = delete;
    Subcommand& operator=(Subcommand&&) = delete;
    virtual ~Subcommand() = default;

    [[nodiscard]] virtual std::string name() const = 0;
    [[nodiscard]] virtual std::string description() const = 0;
    /// Adds the subcommand's options and positionals to @p command.
    virtual void define(CLI::App& command) = 0;
    /// Runs the tool with the parsed options; returns the process exit code.
    [[nodiscard]] virtual int run(std::optional<config::LogLevel> log_level) = 0;
};

/// `--config FILE`: run the gateway in the foreground.
struct RunCommand {
    std::filesystem::path config_file;
    std::optional<config::LogLevel> log_level;  ///< --log-level; overrides gateway.log_level
};

/// `--check-config FILE`: validate and exit.
struct CheckConfigCommand {
    std::filesystem::path config_file;
};

/// A registered subcommand was chosen; its options are already parsed into it.
struct SubcommandCommand {
    Subcommand* subcommand = nullptr;
    std::optional<config::LogLevel> log_level;
};

/// Nothing left to do but exit: help or version was printed (exit 0), or a usage
/// error was reported on the error stream (exit_usage).
struct ExitCommand {
    int exit_code = 0;
};

using Command = std::variant<RunCommand, CheckConfigCommand, SubcommandCommand, ExitCommand>;

class CommandLine {
public:
    /// @p version is printed by --version ("fieldbridge <version>").
    explicit CommandLine(std::string version);

    /// Registers @p subcommand (not owned; must outlive parse() and its result).
    void add_subcommand(Subcommand& subcommand);

    /// Parses @p argv. Help and version go to @p out, usage errors to @p err with a
    /// hint to run --help; every usage error maps to exit_usage (64).
    [[nodiscard]] Command parse(int argc, const char* const* argv, std::ostream& out, std::ostream& err) const;

private:
    std::string version_;
    std::vector<Subcommand*> subcommands_;
};

}  // namespace fieldbridge::daemon
