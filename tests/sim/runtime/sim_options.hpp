#pragma once
/// @file sim_options.hpp
/// Command-line options of fieldbridge-sim in three steps: CLI11 fills RawOptions
/// (strings as typed), build_options() checks and converts them, the Simulator gets
/// an immutable SimOptions.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/App.hpp>

#include "fault_plan.hpp"
#include "models/device_factory.hpp"

namespace fieldbridge::sim::runtime {

struct DeviceSpec {
    std::string type;
    std::uint8_t address = 0;
    DeviceOptions options;
};

struct BusSpec {
    std::filesystem::path link;   ///< where the pty's slave side is linked
    std::string name;             ///< file name of the link: "line-a"
    std::vector<DeviceSpec> devices;
};

struct Endpoint {
    std::string host;
    std::uint16_t port = 0;
};

struct SimOptions {
    std::vector<BusSpec> buses;
    std::optional<Endpoint> r6;
    std::optional<std::uint8_t> r6_unit;  ///< nullopt: answer every unit id
    bool wire_time = false;
    unsigned baud = 115200;
    char parity = 'N';
    unsigned stop_bits = 1;
    std::chrono::nanoseconds turnaround = std::chrono::milliseconds(1);
    std::chrono::nanoseconds tick = std::chrono::milliseconds(10);
    std::optional<std::chrono::nanoseconds> duration;
    std::optional<std::filesystem::path> control;
    std::optional<std::filesystem::path> stats_file;
    std::optional<std::uint64_t> seed;
    std::vector<FaultSpec> faults;
    std::string log_level = "info";
};

/// The options as typed, filled by CLI11.
struct RawOptions {
    std::vector<std::string> buses;
    std::string r6;
    int r6_unit = -1;
    bool wire_time = false;
    unsigned baud = 115200;
    std::string parity = "N";
    unsigned stop_bits = 1;
    std::string turnaround = "1ms";
    std::string tick = "10ms";
    std::string duration;
    std::string control;
    std::string stats_file;
    std::string seed;
    std::vector<std::string> faults;
    std::string xeg_model = "0x0A20";
    std::uint32_t wtec_stroke = DeviceOptions{}.wtec_stroke;
    std::string excd_word_order = DeviceOptions{}.excd_word_order;
    std::string log_level = "info";
    std::vector<std::string> definition_dirs;   ///< --definitions
    std::vector<std::string> definition_files;  ///< --definition
};

/// Declares every option on @p app, bound to @p raw, with its --help text.
void add_options(CLI::App& app, RawOptions& raw);

/// Checks and converts. Throws SimError naming the option and what to write instead.
[[nodiscard]] SimOptions build_options(const RawOptions& raw);

/// "PATH:TYPE@ADDR[/key=value...],TYPE@ADDR..." (keys: model, stroke, word-order).
[[nodiscard]] BusSpec parse_bus_spec(std::string_view text, const DeviceOptions& defaults);

/// Gives every device of @p buses whose type is not a built-in model the device
/// definition of that name: a file of @p files whose name is NAME.yaml, else
/// NAME.yaml in the first of @p dirs that has it (sim_definitions.cpp). Throws
/// SimError naming the device and what was searched, or the definition's problems
/// (file:line:col).
void attach_definitions(std::vector<BusSpec>& buses, const std::vector<std::string>& dirs,
                        const std::vector<std::string>& files);

/// "HOST:PORT" (IPv4 or bracketed IPv6).
[[nodiscard]] Endpoint parse_endpoint(std::string_view text, std::string_view what);

}  // namespace fieldbridge::sim::runtime
