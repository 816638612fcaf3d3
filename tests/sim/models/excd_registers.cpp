#include "models/excd_registers.hpp"

namespace fieldbridge::sim {
namespace {

constexpr std::int64_t pos_min = excd_position_min;
constexpr std::int64_t pos_max = excd_position_max;
constexpr std::uint16_t last_address = 0x04F8;

// seed 002 section 4, in the manual's order. Initial values are the simulator's
// (the manual gives none): plausible factory settings inside each range.
std::vector<ExcdRegister> build_entries() {
    using K = ExcdKind;
    std::vector<ExcdRegister> e = {
        // system commands
        {"hdir", 0x0000, 1, K::setting, 0, 1, 0, 0},
        {"hvs", 0x0001, 1, K::setting, 1, 0x1388, 100, 0},
        {"htr", 0x0002, 2, K::setting, 1, 0x927C0, 10000, 0},
        {"hvr", 0x0004, 2, K::setting, 1, 0x7A120, 2000, 0},
        {"hsd", 0x0006, 1, K::setting, 1, 0xFA, 10, 0},
        {"jvs", 0x0007, 1, K::setting, 1, 0x1388, 100, 0},
        {"jtr", 0x0008, 2, K::setting, 1, 0x927C0, 10000, 0},
        {"jvr", 0x000A, 2, K::setting, 1, 0x7A120, 1000, 0},
        {"svs", 0x000C, 1, K::setting, 1, 0x1388, 100, 0},
        {"str", 0x000D, 2, K::setting, 1, 0x927C0, 10000, 0},
        {"svr", 0x000F, 2, K::setting, 1, 0x7A120, 10000, 0},
        {"div", 0x0011, 1, K::setting, 0xC8, 0xC800, 3200, 0},
        {"cur", 0x0012, 1, K::setting, 0x0A, 0x1E, 20, 0},
        {"solmsw", 0x0013, 1, K::setting, 0, 2, 0, 0},
        {"solm+", 0x0014, 2, K::setting, pos_min, pos_max, pos_max, 0},
        {"solm-", 0x0016, 2, K::setting, pos_min, pos_max, pos_min, 0},
        {"hty", 0x0018, 1, K::setting, 0, 1, 0, 0},
        {"lty+", 0x0019, 1, K::setting, 0, 1, 0, 0},
        {"lty-", 0x001A, 1, K::setting, 0, 1, 0, 0},
        {"sty", 0x001B, 1, K::setting, 0, 1, 0, 0},
        {"oclr", 0x001C, 1, K::setting, 0, 1, 0, 0},
        {"auto", 0x001D, 1, K::setting, 0, 1, 0, 0},
        {"hold", 0x001E, 1, K::setting, 0, 1, 0, 0},
        {"idon", 0x001F, 1, K::setting, 0, 1, 0, 0},
        {"id", 0x0020, 1, K::setting, 0, 0x3F, 1, 0},
        {"pulse", 0x0021, 1, K::setting, 0, 1, 0, 0},
        {"pitch", 0x0022, 2, K::setting, 1, 0x1869F, 100, 0},
        {"hfset", 0x0024, 2, K::setting, pos_min, pos_max, 0, 0},
        {"curdwn", 0x0026, 1, K::setting, 0, 0x64, 50, 0},
        {"extvr", 0x0027, 1, K::setting, 0, 1, 0, 0},
        {"htime", 0x0028, 1, K::setting, 5, 0x64, 10, 0},
        {"intime", 0x0029, 1, K::setting, 5, 0x64, 10, 0},
        {"stime", 0x002A, 1, K::setting, 5, 0x64, 10, 0},
        {"baude", 0x002B, 2, K::setting, 0x4B0, 0x1C200, 115200, 0},
        {"hmode", 0x002D, 1, K::setting, 0, 1, 0, 0},
        {"hloop", 0x002E, 1, K::setting, 1, 0xFA, 1, 0},
        {"ifinbit", 0x002F, 1, K::setting, 0, 1, 0, 0},
        {"curdwnt", 0x0030, 2, K::setting, 0x64, 0x36EE80, 1000, 0},
        // EXCD203MB-E only; the simulator is an -E.
        {"mdir", 0x0032, 1, K::setting, 0, 1, 0, 0},
        {"clr", 0x0033, 1, K::setting, 0, 0, 0, 0},
        {"encdiv", 0x0034, 1, K::setting, 0, 0, 0, 0},
        {"enc", 0x0035, 1, K::setting, 0, 2, 0, 0},
        {"homez", 0x0036, 1, K::setting, 0, 0x64, 0, 0},
        {"edir", 0x0037, 1, K::setting, 0, 1, 0, 0},
        {"zty", 0x0038, 1, K::setting, 0, 1, 0, 0},
        {"curm", 0x0039, 1, K::setting, 5, 0x1E, 10, 0},
        {"mbus", 0x003A, 1, K::setting, 0, 1, 1, 0},
        {"make", 0x003B, 1, K::setting, 1, 0x32, 1, 0},
        {"prr", 0x003C, 1, K::setting, 0, 0xFF, 0, 0},
        // motion commands
        {"abs", 0x0100, 2, K::motion, pos_min, pos_max, 0, 0},
        {"sabs", 0x0102, 2, K::motion, pos_min, pos_max, 0, 0},
        {"rel", 0x0104, 2, K::motion, pos_min, pos_max, 0, 0},
        {"start", 0x0106, 1, K::motion, 0, 0, 0, 0},
        {"home", 0x0107, 1, K::motion, 0, 0, 0, 0},
        {"stop", 0x0108, 1, K::motion, 0, 0, 0, 0},
        {"mstop", 0x0109, 1, K::motion, 0, 0, 0, 0},
        {"jog", 0x010A, 2, K::motion, pos_min, pos_max, 0, 0},
        {"jogstop", 0x010C, 1, K::motion, 0, 0, 0, 0},
        // query commands
        {"rms", 0x0200, 1, K::query, 0, 0, 0, 0},
        {"rabs", 0x0201, 2, K::query, 0, 0, 0, 0},
        {"rin", 0x0203, 1, K::query, 0, 0, 0, 0},
        {"rout", 0x0204, 1, K::query, 0, 0, 0, 0},
        {"rby", 0x0205, 1, K::query, 0, 0, 0, 0},
        {"sensor", 0x0206, 1, K::query, 0, 0, 0, 0},
        {"ver", 0x0207, 2, K::query, 0, 0, 0, 0},
        {"rse", 0x0209, 1, K::query, 0, 0, 0, 0},
        {"rsa", 0x020A, 1, K::query, 0, 0, 0, 0},
        {"renc", 0x02D4, 2, K::query, 0, 0, 0, 0},
        {"ralarm", 0x02D6, 1, K::query, 0, 0, 0, 0},
        // I/O and other commands
        {"outon", 0x0300, 1, K::io, 0, 0x0F, 0, 0},
        {"clear", 0x0301, 1, K::io, 0, 0, 0, 0},
        {"outoff", 0x0302, 1, K::io, 0, 0x0F, 0, 0},
        {"save", 0x0303, 1, K::save, 0, 0, 0, 0},
    };
    for (std::uint8_t i = 1; i <= 50; ++i) {
        e.push_back({"rcount", static_cast<std::uint16_t>(0x020C + 2 * (i - 1)), 2, K::count_read,
                     0, 0, 0, i});
        e.push_back({"cnt", static_cast<std::uint16_t>(0x0270 + 2 * (i - 1)), 2, K::count_write,
                     pos_min, pos_max, 0, i});
        e.push_back({"rstcount", static_cast<std::uint16_t>(0x04C7 + (i - 1)), 1, K::count_reset,
                     0, 0, 0, i});
    }
    for (std::uint8_t i = 1; i <= 99; ++i) {
        e.push_back({"n", static_cast<std::uint16_t>(0x0401 + 2 * (i - 1)), 2, K::variable,
                     pos_min, pos_max, 0, i});
    }
    return e;
}

}  // namespace

ExcdRegisterTable::ExcdRegisterTable()
    : entries_(build_entries()), by_address_(std::size_t{last_address} + 1, -1) {
    for (std::size_t i = 0; i < entries_.size(); ++i) {
        for (std::uint8_t w = 0; w < entries_[i].words; ++w) {
            by_address_[entries_[i].address + w] = static_cast<std::int16_t>(i);
        }
    }
}

const ExcdRegister* ExcdRegisterTable::covering(std::uint16_t address) const noexcept {
    if (address >= by_address_.size() || by_address_[address] < 0) return nullptr;
    return &entries_[static_cast<std::size_t>(by_address_[address])];
}

std::size_t ExcdRegisterTable::index_of(const ExcdRegister& entry) const noexcept {
    return static_cast<std::size_t>(&entry - entries_.data());
}

}  // namespace fieldbridge::sim
