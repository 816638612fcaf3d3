#include "scan/scan_report.hpp"

#include <sstream>

namespace fieldbridge::scan {

namespace {

/// The `stroke` written for a WTEC ASCII device. The ASCII protocol has no query for
/// the encoder counts at 100 % (seed 003): this is the value of the example
/// configuration, and the comment says to measure the real one.
constexpr std::uint32_t assumed_wtec_stroke = 20000;

/// Comment text on one line, whatever a device reports.
[[nodiscard]] std::string one_line(const std::string& text) {
    std::string out;
    for (const char c : text) {
        out.push_back(c == '\n' || c == '\r' ? ' ' : c);
    }
    return out;
}

}  // namespace

std::string suggested_name(const FoundDevice& device) {
    const std::string type = device.definition.empty() ? std::string{engine::to_string(device.type)} : device.definition;
    return type + "-" + std::to_string(device.address);
}

std::string config_snippet(const ScannedLine& line, const std::vector<FoundDevice>& devices) {
    std::ostringstream out;
    out << "# fieldbridge scan of " << line.port << ": " << devices.size()
        << (devices.size() == 1 ? " device" : " devices") << " found.\n"
        << "# Paste under the line's entry in lines[] (docs/configuration.md), with\n"
        << "#   port: " << line.port << "\n"
        << "#   baud: " << line.baud << "\n"
        << "#   parity: " << core::to_string(line.parity) << "\n"
        << "#   stop_bits: " << line.stop_bits << "\n"
        << "# unit_id is the bus address: renumber when another line uses the same IDs.\n"
        << "devices:\n";
    for (const FoundDevice& d : devices) {
        out << "  - name: " << suggested_name(d) << "\n"
            << "    # " << one_line(d.detail) << "\n"
            << "    type: " << (d.definition.empty() ? std::string{engine::to_string(d.type)} : d.definition) << "\n"
            << "    address: " << unsigned{d.address} << "\n"
            << "    unit_id: " << unsigned{d.address} << "\n";
        if (d.type == engine::DeviceType::wtec_ascii) {
            out << "    # stroke cannot be read over the bus: measure the encoder counts at 100 %\n"
                << "    # (N's target at both ends) and correct this value.\n"
                << "    stroke: " << assumed_wtec_stroke << "\n";
        } else if (d.type == engine::DeviceType::modbus && d.definition.empty()) {
            out << (d.holding_zero_readable ? "    # holding register 0x0000 answered; add the device's other registers\n"
                                            : "    # the register map is unknown (0x0000 answered with an exception):\n"
                                              "    # replace this block with the device's registers\n")
                << "    blocks:\n"
                << "      - { table: holding, address: 0x0000, count: 1 }\n";
        }
    }
    return out.str();
}

}  // namespace fieldbridge::scan
