#include "load_shape.hpp"

#include <fmt/format.h>

#include <stdexcept>

namespace fieldbridge::bench {
namespace {

constexpr std::uint16_t xeg_status = 0x0300;  // position + status, input registers
constexpr std::uint16_t generic_spread = 100;  // FC03 at 0..99
// A step prime to the spread, so consecutive reads to one device move about.
constexpr std::uint64_t generic_step = 37;

}  // namespace

LoadShape LoadShape::parse(std::string_view name) {
    if (name == "xeg") return LoadShape(Kind::xeg);
    if (name == "generic") return LoadShape(Kind::generic);
    throw std::invalid_argument("unknown load shape \"" + std::string(name) + "\"; use xeg or generic");
}

std::string_view LoadShape::name() const noexcept { return kind_ == Kind::xeg ? "xeg" : "generic"; }

std::string_view LoadShape::description() const noexcept {
    return kind_ == Kind::xeg ? "1 HIWIN XEG, FC04 0x0300 x2"
                              : "4 generic modbus devices in turn, FC03 x2 at addresses 0-99";
}

std::uint8_t LoadShape::bus_address(std::size_t device) const noexcept {
    return kind_ == Kind::xeg ? std::uint8_t{2} : static_cast<std::uint8_t>(1 + device);
}

ShapeRead LoadShape::read(std::uint64_t n) const noexcept {
    if (kind_ == Kind::xeg) return ShapeRead{0, 0x04, xeg_status, 2};
    return ShapeRead{static_cast<std::size_t>(n % 4), 0x03,
                     static_cast<std::uint16_t>((n / 4 * generic_step) % generic_spread), 2};
}

std::string LoadShape::sim_devices() const {
    if (kind_ == Kind::xeg) return "hiwin-xeg@2";
    return "modbus@1,modbus@2,modbus@3,modbus@4";
}

std::string LoadShape::daemon_devices(std::uint8_t first_unit) const {
    if (kind_ == Kind::xeg) {
        return fmt::format(R"(      - name: xeg-direct
        type: hiwin-xeg
        address: {}
        unit_id: {}
        max_age: 0ms
        queue_limit: 64
        poll: {{ fast: 60min, slow: 60min, motion: 60min }}
)",
                           bus_address(0), first_unit);
    }
    std::string yaml;
    for (std::size_t d = 0; d < devices(); ++d) {
        // Registers 0-103: the reads' 0-100 and the write's 0x10; read once at start,
        // then only on demand.
        yaml += fmt::format(R"(      - name: generic-{0}
        type: modbus
        address: {0}
        unit_id: {1}
        max_age: 0ms
        queue_limit: 64
        blocks:
          - {{ table: holding, address: 0, count: 104, period: 1h, writable: true }}
)",
                            bus_address(d), first_unit + d);
    }
    return yaml;
}

}  // namespace fieldbridge::bench
