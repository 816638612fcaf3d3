#pragma once
/// @file line_scanner.hpp
/// The discovery of one line: which WTEC-485 ASCII stations answer `$`, then a
/// Modbus-RTU probe of every other address of the range (device_probe.hpp), each
/// request through a LineLink. Reports progress through a callback.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "engine/transaction.hpp"
#include "scan/device_probe.hpp"
#include "scan/line_link.hpp"

namespace fieldbridge::scan {

struct ScanRange {
    std::uint8_t first = 1;
    std::uint8_t last = 247;
};

struct ScanStats {
    unsigned requests = 0;
    unsigned timeouts = 0;
    engine::Duration elapsed{};
};

struct ScanResult {
    std::vector<FoundDevice> devices;  ///< ascending address
    ScanStats stats;
};

class LineScanner {
public:
    /// One line of progress text ("address 2: hiwin-xeg, XEG-32 (model <model code>)").
    using Progress = std::function<void(const std::string&)>;

    /// @p definitions: the identify reads of device definitions, tried on every
    /// Modbus device that is none of the built-in types (device_probe.hpp).
    LineScanner(LineLink& link, ScanRange range, Progress progress = {},
                std::vector<DefinitionIdentify> definitions = {});

    /// Runs the whole scan. Throws engine::SerialPortError when the port fails.
    [[nodiscard]] ScanResult run();

private:
    [[nodiscard]] std::vector<FoundDevice> find_ascii_stations(ScanStats& stats);
    [[nodiscard]] std::optional<FoundDevice> probe_modbus(std::uint8_t address, ScanStats& stats);
    [[nodiscard]] engine::Outcome send(engine::Payload payload, std::uint8_t address, ScanStats& stats,
                                       protocol::Bytes* received = nullptr);
    void report(const std::string& text) const;

    LineLink& link_;
    ScanRange range_;
    Progress progress_;
    std::vector<DefinitionIdentify> definitions_;
};

}  // namespace fieldbridge::scan
