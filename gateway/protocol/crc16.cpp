#include "protocol/crc16.hpp"

#include <array>

namespace fieldbridge::protocol {
namespace {

// Reflected form of the polynomial x^16 + x^15 + x^2 + 1 (Modbus over Serial Line
// V1.02, 6.2.2: "the polynomial value 0xA001").
constexpr std::uint16_t reflected_polynomial = 0xA001;

/// One entry per byte value: the register after shifting that byte through it,
/// bit by bit, from zero. Computed at compile time, read-only at run time.
constexpr std::array<std::uint16_t, 256> make_table() noexcept {
    std::array<std::uint16_t, 256> table{};
    for (std::size_t byte = 0; byte < table.size(); ++byte) {
        auto reg = static_cast<std::uint16_t>(byte);
        for (int bit = 0; bit < 8; ++bit) {
            const bool lsb = (reg & 1U) != 0;
            reg = static_cast<std::uint16_t>(reg >> 1);
            if (lsb) reg = static_cast<std::uint16_t>(reg ^ reflected_polynomial);
        }
        table[byte] = reg;
    }
    return table;
}

constexpr std::array<std::uint16_t, 256> crc_table = make_table();

// Spot checks of the generated table against the published CRC-16/MODBUS table.
static_assert(crc_table[0x00] == 0x0000);
static_assert(crc_table[0x01] == 0xC0C1);
static_assert(crc_table[0x80] == 0xA001);
static_assert(crc_table[0xFF] == 0x4040);

}  // namespace

std::uint16_t crc16_modbus_update(std::uint16_t crc, ByteView data) noexcept {
    for (const std::uint8_t byte : data) {
        const auto index = static_cast<std::uint8_t>((crc ^ byte) & 0xFFU);
        crc = static_cast<std::uint16_t>((crc >> 8) ^ crc_table[index]);
    }
    return crc;
}

std::uint16_t crc16_modbus(ByteView data) noexcept {
    return crc16_modbus_update(crc16_modbus_init, data);
}

}  // namespace fieldbridge::protocol
