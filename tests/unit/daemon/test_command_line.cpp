#include <CLI/CLI.hpp>
#include <doctest/doctest.h>

#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "daemon/command_line.hpp"
#include "daemon/exit_codes.hpp"

namespace daemon_ns = fieldbridge::daemon;
using fieldbridge::config::LogLevel;

namespace {

/// A subcommand shaped like the future `scan --port DEV [--baud N]`.
class ScanLike final : public daemon_ns::Subcommand {
public:
    std::string port;
    unsigned baud = 115200;
    std::optional<LogLevel> run_level;
    int runs = 0;

    [[nodiscard]] std::string name() const override { return "scan"; }
    [[nodiscard]] std::string description() const override { return "Scan a line"; }
    void define(CLI::App& command) override {
        command.add_option("--port", port, "Serial device")->required();
        command.add_option("--baud", baud, "Bit rate");
    }
    [[nodiscard]] int run(std::optional<LogLevel> log_level) override {
        run_level = log_level;
        ++runs;
        return 7;
    }
};

struct Parsed {
    daemon_ns::Command command;
    std::string out;
    std::string err;
};

[[nodiscard]] Parsed parse(const daemon_ns::CommandLine& cli, std::vector<std::string> args) {
    args.insert(args.begin(), "fieldbridge");
    std::vector<const char*> argv;
    for (const auto& arg : args) {
        argv.push_back(arg.c_str());
    }
    std::ostringstream out;
    std::ostringstream err;
    auto command = cli.parse(static_cast<int>(argv.size()), argv.data(), out, err);
    return Parsed{std::move(command), out.str(), err.str()};
}

[[nodiscard]] int exit_code_of(const Parsed& parsed) {
    REQUIRE(std::holds_alternative<daemon_ns::ExitCommand>(parsed.command));
    return std::get<daemon_ns::ExitCommand>(parsed.command).exit_code;
}

}  // namespace

TEST_CASE("--config runs the gateway, with an optional log level override") {
    const daemon_ns::CommandLine cli("1.2.3");
    auto parsed = parse(cli, {"--config", "/etc/fieldbridge/fieldbridge.yaml"});
    REQUIRE(std::holds_alternative<daemon_ns::RunCommand>(parsed.command));
    auto run = std::get<daemon_ns::RunCommand>(parsed.command);
    CHECK(run.config_file == "/etc/fieldbridge/fieldbridge.yaml");
    CHECK_FALSE(run.log_level.has_value());

    parsed = parse(cli, {"-c", "a.yaml", "--log-level", "debug"});
    REQUIRE(std::holds_alternative<daemon_ns::RunCommand>(parsed.command));
    run = std::get<daemon_ns::RunCommand>(parsed.command);
    CHECK(run.config_file == "a.yaml");
    CHECK(run.log_level == LogLevel::debug);

    parsed = parse(cli, {"--log-level=warning", "--config=b.yaml"});
    REQUIRE(std::holds_alternative<daemon_ns::RunCommand>(parsed.command));
    CHECK(std::get<daemon_ns::RunCommand>(parsed.command).log_level == LogLevel::warning);
}

TEST_CASE("--check-config validates a file") {
    const daemon_ns::CommandLine cli("1.2.3");
    const auto parsed = parse(cli, {"--check-config", "x.yaml"});
    REQUIRE(std::holds_alternative<daemon_ns::CheckConfigCommand>(parsed.command));
    CHECK(std::get<daemon_ns::CheckConfigCommand>(parsed.command).config_file == "x.yaml");
}

TEST_CASE("--version and --help print on stdout and exit 0") {
    const daemon_ns::CommandLine cli("1.2.3");
    auto parsed = parse(cli, {"--version"});
    CHECK(exit_code_of(parsed) == daemon_ns::exit_ok);
    CHECK(parsed.out == "fieldbridge 1.2.3\n");
    CHECK(parsed.err.empty());

    parsed = parse(cli, {"--help"});
    CHECK(exit_code_of(parsed) == daemon_ns::exit_ok);
    CHECK(parsed.out.find("--check-config") != std::string::npos);
    CHECK(parsed.out.find("64 usage error") != std::string::npos);
}

TEST_CASE("usage errors exit 64 with a message on stderr") {
    const daemon_ns::CommandLine cli("1.2.3");
    const std::vector<std::vector<std::string>> wrong{
        {},                                                  // nothing to do
        {"--bogus"},                                         // unknown option
        {"--config"},                                        // missing value
        {"--config", "a", "--check-config", "b"},            // two modes
        {"--check-config", "b", "--log-level", "debug"},     // level has no meaning there
        {"--config", "a", "--log-level", "verbose"},         // not a level
        {"--config", "a", "extra"},                          // stray positional
        {"--log-level", "info"},                             // a level but no mode
    };
    for (const auto& args : wrong) {
        CAPTURE(args.size());
        const auto parsed = parse(cli, args);
        CHECK(exit_code_of(parsed) == daemon_ns::exit_usage);
        CHECK(parsed.err.find("--help") != std::string::npos);
        CHECK(parsed.out.empty());
    }
}

TEST_CASE("subcommands plug in and get their own options") {
    ScanLike scan;
    daemon_ns::CommandLine cli("1.2.3");
    cli.add_subcommand(scan);

    auto parsed = parse(cli, {"--log-level", "trace", "scan", "--port", "/dev/ttyUSB0", "--baud", "9600"});
    REQUIRE(std::holds_alternative<daemon_ns::SubcommandCommand>(parsed.command));
    const auto chosen = std::get<daemon_ns::SubcommandCommand>(parsed.command);
    CHECK(chosen.subcommand == &scan);
    CHECK(chosen.log_level == LogLevel::trace);
    CHECK(scan.port == "/dev/ttyUSB0");
    CHECK(scan.baud == 9600);
    CHECK(chosen.subcommand->run(chosen.log_level) == 7);
    CHECK(scan.runs == 1);

    parsed = parse(cli, {"scan"});  // --port is required by the subcommand
    CHECK(exit_code_of(parsed) == daemon_ns::exit_usage);

    parsed = parse(cli, {"--config", "a.yaml", "scan", "--port", "/dev/ttyUSB0"});
    CHECK(exit_code_of(parsed) == daemon_ns::exit_usage);
    CHECK(parsed.err.find("scan") != std::string::npos);

    parsed = parse(cli, {"--config", "a.yaml"});  // the daemon still runs without it
    CHECK(std::holds_alternative<daemon_ns::RunCommand>(parsed.command));
}
