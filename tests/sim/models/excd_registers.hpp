#pragma once
/// @file excd_registers.hpp
/// The holding-register table of the EXCD203MB stepper controller (seed 002, section 4
/// "定義說明"): every command with its address, size (1 register or a 32-bit pair), what
/// the host may do with it, the manual's input range and the simulator's initial value.

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

namespace fieldbridge::sim {

enum class ExcdKind : std::uint8_t {
    setting,        ///< system command (0x0000-0x003C): read/write, stored
    motion,         ///< motion command (0x0100-0x010C): write acts, read gives the last value
    query,          ///< query command (0x0200-0x020A, 0x02D4-0x02D6): read only
    count_read,     ///< rcount1-50 (0x020C-0x026F): read only
    count_write,    ///< cnt1-50 (0x0270-0x02D3): read/write of the same counters
    io,             ///< outon / clear / outoff (0x0300-0x0302)
    save,           ///< save (0x0303)
    variable,       ///< n01-n99 (0x0401-0x04C6)
    count_reset,    ///< rstcount1-50 (0x04C7-0x04F8)
};

struct ExcdRegister {
    std::string_view name;
    std::uint16_t address = 0;
    std::uint8_t words = 1;   ///< 1, or 2 for a 32-bit pair
    ExcdKind kind = ExcdKind::setting;
    std::int64_t min = 0;     ///< manual's range; pairs of position type are signed 32-bit
    std::int64_t max = 0;
    std::int64_t initial = 0;
    std::uint8_t index = 0;   ///< counter or variable number (1-based) for the numbered kinds
};

/// Position-type range of the manual: 0xFF815A20 - 0x007EA5E0.
inline constexpr std::int64_t excd_position_min = -8'300'000;
inline constexpr std::int64_t excd_position_max = 8'300'000;

/// Lookup of the register table by address.
class ExcdRegisterTable {
public:
    ExcdRegisterTable();

    /// The entry that covers @p address (its first or second register), or nullptr.
    [[nodiscard]] const ExcdRegister* covering(std::uint16_t address) const noexcept;
    [[nodiscard]] const std::vector<ExcdRegister>& entries() const noexcept { return entries_; }
    /// Position of @p entry in entries(), for per-entry storage.
    [[nodiscard]] std::size_t index_of(const ExcdRegister& entry) const noexcept;

private:
    std::vector<ExcdRegister> entries_;
    std::vector<std::int16_t> by_address_;  ///< entry index per address, -1 for none
};

}  // namespace fieldbridge::sim
