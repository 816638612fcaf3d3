#include "engine/profiles/generic_profile.hpp"

#include <algorithm>
#include <set>
#include <string>
#include <utility>

#include "engine/profiles/profile_text.hpp"

namespace fieldbridge::engine {

namespace {

[[nodiscard]] std::string describe(const GenericBlock& b) {
    return std::string{to_string(b.table)} + " block at " + hex_word(b.address) + " (count " +
           std::to_string(b.count) + ")";
}

void check_block(const GenericBlock& b) {
    const std::uint16_t limit = is_bit_table(b.table) ? max_block_bits : max_block_registers;
    if (b.count == 0 || b.count > limit) {
        throw ProfileError("modbus device: " + describe(b) + ": count must be 1-" + std::to_string(limit) +
                           " (one read); split the block");
    }
    if (std::size_t{b.address} + b.count > 0x10000) {
        throw ProfileError("modbus device: " + describe(b) + " runs past address 0xFFFF; shorten it");
    }
    if (b.writable && (b.table == Table::discrete_inputs || b.table == Table::input)) {
        throw ProfileError("modbus device: " + describe(b) +
                           " is marked writable, but Modbus cannot write that table; remove `writable`");
    }
    if (b.period <= Duration::zero()) {
        throw ProfileError("modbus device: " + describe(b) + ": the poll period must be positive");
    }
}

/// The blocks may overlap (the same registers at two periods): the map is their
/// union, cut where any block starts or ends; a piece is writable when any block
/// covering it is.
[[nodiscard]] std::shared_ptr<const RegisterMap> build_map(const std::vector<GenericBlock>& blocks) {
    if (blocks.empty()) {
        throw ProfileError("modbus device: no register blocks configured; add `blocks:` with table, address, count");
    }
    std::vector<RegisterDef> defs;
    for (std::size_t t = 0; t < table_count; ++t) {
        const auto table = static_cast<Table>(t);
        std::set<std::size_t> cuts;
        for (const GenericBlock& b : blocks) {
            check_block(b);
            if (b.table == table) {
                cuts.insert(b.address);
                cuts.insert(std::size_t{b.address} + b.count);
            }
        }
        for (auto it = cuts.begin(); it != cuts.end() && std::next(it) != cuts.end(); ++it) {
            const std::size_t from = *it;
            const std::size_t to = *std::next(it);
            bool covered = false;
            bool writable = false;
            for (const GenericBlock& b : blocks) {
                if (b.table == table && b.address <= from && to <= std::size_t{b.address} + b.count) {
                    covered = true;
                    writable = writable || b.writable;
                }
            }
            if (!covered) {
                continue;  // a gap between blocks: a hole
            }
            RegisterDef d;
            d.table = table;
            d.address = static_cast<std::uint16_t>(from);
            d.count = static_cast<std::uint16_t>(to - from);
            d.access = writable ? Access::read_write : Access::read;
            d.max = is_bit_table(table) ? 1 : 0xFFFF;
            d.name = std::string{to_string(table)} + " " + hex_word(d.address);
            defs.push_back(std::move(d));
        }
    }
    return std::make_shared<const RegisterMap>(std::move(defs));
}

[[nodiscard]] WireFunctions generic_wire_functions() {
    namespace fn = protocol::fn;
    // What libmodbus' server and mbusd carry too: report server ID (FC11), mask write
    // (FC16) and read/write multiple registers (FC17), through the same block checks.
    return WireFunctions{{fn::read_coils, fn::read_discrete_inputs, fn::read_holding_registers,
                          fn::read_input_registers, fn::write_single_coil, fn::write_single_register,
                          fn::write_multiple_coils, fn::write_multiple_registers, fn::report_server_id,
                          fn::mask_write_register, fn::read_write_multiple_registers},
                         false, false};
}

}  // namespace

GenericProfile::GenericProfile(const ProfileOptions& options)
    : ModbusProfile(build_map(options.blocks), generic_wire_functions(), options, WordOrder::high_first) {}

std::vector<PollUnit> GenericProfile::poll_units() const {
    std::vector<PollUnit> units;
    for (const GenericBlock& b : options().blocks) {
        auto more = map().poll_units(RegisterSpan{b.table, b.address, b.count}, PollClass::custom, b.period, false);
        units.insert(units.end(), more.begin(), more.end());
    }
    return units;
}

bool GenericProfile::in_motion(const RegisterImage& /*image*/) const {
    return false;
}

DecodedState GenericProfile::decode_state(const RegisterImage& /*image*/) const {
    return {};
}

std::vector<Alarm> GenericProfile::alarms(const RegisterImage& /*image*/) const {
    return {};
}

}  // namespace fieldbridge::engine
