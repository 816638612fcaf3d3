#pragma once
/// @file scan_report.hpp
/// The configuration snippet a scan prints: a `devices:` list in the format of
/// docs/configuration.md (lines[].devices[]), ready to paste under the line's entry.
/// Pure text generation.

#include <cstdint>
#include <string>
#include <vector>

#include "scan/device_probe.hpp"

#include "core/parity.hpp"

namespace fieldbridge::scan {

/// The line the devices were found on, for the snippet's header comment.
struct ScannedLine {
    std::string port;
    std::uint32_t baud = 115200;
    core::Parity parity = core::Parity::none;
    unsigned stop_bits = 1;
};

/// Suggested device name: the type (or definition) and the address ("hiwin-xeg-2"),
/// unique on a line.
[[nodiscard]] std::string suggested_name(const FoundDevice& device);

/// The snippet for @p devices (not empty): a comment naming the line settings to
/// use, then `devices:` with name, type, address and unit_id (= the address, unique
/// on one line; renumber when several lines share a gateway) for each, plus the keys
/// a type requires: `stroke` for wtec-ascii (which no command reads: marked to be
/// measured), `blocks` for generic modbus devices; a device a definition identified
/// has the definition's name as its type and needs nothing more.
[[nodiscard]] std::string config_snippet(const ScannedLine& line, const std::vector<FoundDevice>& devices);

}  // namespace fieldbridge::scan
