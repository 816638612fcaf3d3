// The configuration snippet of a scan (scan/scan_report.hpp). That the snippet is
// accepted by --check-config is tested on the real binary (tests/integration/scan).

#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "scan/scan_report.hpp"

namespace fieldbridge::scan {
namespace {

using engine::DeviceType;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST_CASE("suggested names are the type and the address") {
    CHECK(suggested_name(FoundDevice{2, DeviceType::hiwin_xeg, "", false, {}}) == "hiwin-xeg-2");
    CHECK(suggested_name(FoundDevice{253, DeviceType::wtec_ascii, "", false, {}}) == "wtec-ascii-253");
}

TEST_CASE("the snippet lists every device with name, type, address and unit_id, in order") {
    const std::vector<FoundDevice> devices{
        {2, DeviceType::hiwin_xeg, "XEG-32 (model 0x0A20)", false, {}},
        {3, DeviceType::excd203mb, "ver (0x0207-0x0208) reads 120", true, {}},
        {4, DeviceType::wtec_rtu, "device ID register 0x0303 reads 4", false, {}},
    };
    const std::string text = config_snippet(ScannedLine{"/dev/ttyUSB0", 57600, fieldbridge::core::Parity::even, 2}, devices);
    CHECK(contains(text, "#   port: /dev/ttyUSB0\n#   baud: 57600\n#   parity: even\n#   stop_bits: 2\n"));
    CHECK(contains(text, "\ndevices:\n  - name: hiwin-xeg-2\n    # XEG-32 (model 0x0A20)\n    type: hiwin-xeg\n"
                         "    address: 2\n    unit_id: 2\n  - name: excd203mb-3\n"));
    CHECK(contains(text, "  - name: wtec-rtu-4\n    # device ID register 0x0303 reads 4\n    type: wtec-rtu\n"
                         "    address: 4\n    unit_id: 4\n"));
    CHECK_FALSE(contains(text, "stroke"));
    CHECK_FALSE(contains(text, "blocks"));
}

TEST_CASE("a device a definition identified: the definition's name as type, no block") {
    const FoundDevice device{9, DeviceType::modbus,
                             "device definition acme-meter: its identify read (input 0x0100) is answered", true,
                             "acme-meter"};
    CHECK(suggested_name(device) == "acme-meter-9");
    const std::string text = config_snippet(ScannedLine{"/dev/ttyS1", 9600, fieldbridge::core::Parity::none, 1}, {device});
    CHECK(contains(text, "  - name: acme-meter-9\n    # device definition acme-meter: its identify read (input 0x0100) "
                         "is answered\n    type: acme-meter\n    address: 9\n    unit_id: 9\n"));
    CHECK_FALSE(contains(text, "blocks"));
}

TEST_CASE("wtec-ascii gets the required stroke with a note to measure it") {
    const std::string text = config_snippet(ScannedLine{"/dev/ttyS1", 115200, fieldbridge::core::Parity::none, 1},
                                            {{5, DeviceType::wtec_ascii, "firmware \"Cstep [A]1.62\"", false, {}}});
    CHECK(contains(text, "#   parity: none\n"));
    CHECK(contains(text, "    type: wtec-ascii\n    address: 5\n    unit_id: 5\n"));
    CHECK(contains(text, "cannot be read over the bus"));
    CHECK(contains(text, "    stroke: 20000\n"));
}

TEST_CASE("a generic device gets a block, and text a device sent cannot break a line") {
    const std::string text = config_snippet(ScannedLine{"/dev/ttyS1", 9600, fieldbridge::core::Parity::odd, 1},
                                            {{40, DeviceType::modbus, "odd\ntext", true, {}}});
    CHECK(contains(text, "#   parity: odd\n"));
    CHECK(contains(text, "    # odd text\n"));
    CHECK(contains(text, "    type: modbus\n"));
    CHECK(contains(text, "holding register 0x0000 answered"));
    CHECK(contains(text, "    blocks:\n      - { table: holding, address: 0x0000, count: 1 }\n"));
}

}  // namespace
}  // namespace fieldbridge::scan
