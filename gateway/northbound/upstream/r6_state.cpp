#include "northbound/upstream/r6_state.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <fmt/format.h>
#include <string>
#include <vector>

#include "northbound/upstream/r6_map.hpp"

namespace fieldbridge::northbound::upstream {
namespace {

using engine::Field;
using engine::RegisterImage;
using engine::Table;

std::optional<std::uint16_t> word(const RegisterImage& image, std::uint16_t address) {
    return image.value(Table::holding, address);
}

/// seed 004 section 2: a 32-bit value has its high 16 bits at the lower address.
std::optional<std::int32_t> signed32(const RegisterImage& image, std::uint16_t address) {
    const auto hi = word(image, address);
    const auto lo = word(image, static_cast<std::uint16_t>(address + 1));
    if (!hi || !lo) return std::nullopt;
    return static_cast<std::int32_t>((std::uint32_t{*hi} << 16) | *lo);
}

/// seed 004 section 2: a 64-bit value has its highest 16 bits at the lowest address.
std::optional<std::uint64_t> unsigned64(const RegisterImage& image, std::uint16_t address) {
    std::uint64_t value = 0;
    for (std::uint16_t i = 0; i < 4; ++i) {
        const auto w = word(image, static_cast<std::uint16_t>(address + i));
        if (!w) return std::nullopt;
        value = (value << 16) | *w;
    }
    return value;
}

std::string mode_name(std::uint16_t mode) {
    // seed 004 section 4: 1 manual, 2 auto; 3.1.5's example calls 3 the configuration mode.
    switch (mode) {
        case 1: return "manual";
        case 2: return "auto";
        case 3: return "configuration";
        default: return fmt::format("unknown ({})", mode);
    }
}

std::optional<unsigned> axis_count(const RegisterImage& image) {
    const auto n = word(image, r6::axis_count);
    if (!n) return std::nullopt;
    return std::min<unsigned>(*n, r6::max_axes);
}

double thousandths(std::int32_t raw) { return static_cast<double>(raw) / 1000.0; }

/// @p count signed 32-bit values x1000 from @p address on, as numbers; nullopt unless
/// every one is known (they are polled in one read).
std::optional<std::vector<double>> thousandths_of(const RegisterImage& image, std::uint16_t address,
                                                  unsigned count) {
    std::vector<double> out;
    out.reserve(count);
    for (unsigned i = 0; i < count; ++i) {
        const auto raw = signed32(image, static_cast<std::uint16_t>(address + 2 * i));
        if (!raw) return std::nullopt;
        out.push_back(thousandths(*raw));
    }
    return out;
}

std::int64_t clamp_ms(std::uint64_t ms) {
    constexpr auto max = static_cast<std::uint64_t>(INT64_MAX);
    return static_cast<std::int64_t>(ms > max ? max : ms);
}

}  // namespace

std::optional<protocol::ReadRegistersRequest> r6_poll_read(std::size_t step, const RegisterImage& image) {
    const auto read = [](std::uint16_t address, std::uint16_t count) {
        return protocol::ReadRegistersRequest{protocol::fc::read_holding_registers, address, count};
    };
    switch (step) {
        case 0: return read(r6::mode, 1);
        case 1: return read(r6::axis_count, 1);
        case 2: {
            // seed 004 3.1.8: only existing axes may be read (others are exception 02).
            const auto n = axis_count(image);
            if (!n || *n == 0) return std::nullopt;
            return read(r6::axis_positions, static_cast<std::uint16_t>(2 * *n));
        }
        case 3: return read(r6::world_positions, 2 * r6::world_axes);
        case 4: return read(r6::alarm_number, 1 + 4 + 4);
        case 5: return read(r6::move_state, 2);
        default: return std::nullopt;
    }
}

engine::DecodedState decode_r6_state(const RegisterImage& image) {
    engine::DecodedState out;
    const auto add = [&out](std::string name, engine::FieldValue value, std::string unit = {}) {
        out.fields.push_back(Field{std::move(name), std::move(value), std::move(unit)});
    };
    if (const auto mode = word(image, r6::mode)) {
        add("mode", std::int64_t{*mode});
        add("mode_name", mode_name(*mode));
    }
    if (const auto alarm = word(image, r6::alarm_number)) {
        add("alarm", std::int64_t{*alarm});
        add("alarm_active", *alarm != 0);
    }
    if (const auto moving = word(image, r6::move_state)) add("moving", *moving != 0);
    if (const auto origin = word(image, r6::origin_state)) add("origin_set", *origin != 0);
    if (const auto n = axis_count(image)) {
        add("axis_count", std::int64_t{*n});
        // seed 004 3.1.8: axis 0 is J1; x1000 degrees. Spec §6: one array.
        if (auto axes = thousandths_of(image, r6::axis_positions, *n)) add("axes_deg", std::move(*axes), "deg");
    }
    // seed 004 3.1.9: X Y Z U V W M7 M8, x1000, in mm for every world axis.
    if (auto world = thousandths_of(image, r6::world_positions, r6::world_axes)) {
        add("world_mm", std::move(*world), "mm");
    }
    if (const auto ms = unsigned64(image, r6::cycle_current)) add("cycle_time", clamp_ms(*ms), "ms");
    if (const auto ms = unsigned64(image, r6::cycle_last)) add("last_cycle_time", clamp_ms(*ms), "ms");
    return out;
}

std::vector<engine::Alarm> r6_alarms(const RegisterImage& image) {
    std::vector<engine::Alarm> out;
    const auto alarm = word(image, r6::alarm_number);
    if (alarm && *alarm != 0) {
        out.push_back(engine::Alarm{fmt::format("r6_alarm_{}", *alarm),
                                    fmt::format("R6 controller alarm {} (0x{:04X}); see the R6 alarm list",
                                                *alarm, *alarm),
                                    engine::Severity::error, "holding 0x095C"});
    }
    return out;
}

}  // namespace fieldbridge::northbound::upstream
