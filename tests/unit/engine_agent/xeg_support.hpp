#pragma once
// The HIWIN XEG device of the agent tests (seed 001): its poll items and a
// controller that answers them.

#include <cstdint>
#include <vector>

#include "agent_support.hpp"

namespace fbt::xeg {

constexpr std::uint16_t xeg_32 = 0x0A20;
constexpr std::uint16_t working = 1;
constexpr std::uint16_t positioned = 2;

// The plan (spec §5): model and firmware at start, position + status fast (motion),
// DI and DO slow, as two reads (0x0008-0x000F is a hole).
inline fe::Payload model() { return read_holding(0x0600, 1); }
inline fe::Payload firmware() { return read_input(0x0303, 4); }
inline fe::Payload status() { return read_input(0x0300, 2); }
inline fe::Payload di() { return read_discrete(0x0000, 8); }
inline fe::Payload dout() { return read_discrete(0x0010, 8); }

/// Answers every open poll as an XEG-32 at @p position with @p state.
inline void answer_polls(FakeLine& line, std::uint16_t position = 1000, std::uint16_t state = positioned) {
    for (std::size_t i = 0; i < line.sent.size(); ++i) {
        if (line.sent[i].done || line.at(i).priority != fe::Priority::poll) continue;
        const fe::Transaction& t = line.at(i);
        if (same(t.payload, model())) {
            line.reply(i, registers_reply(t, {xeg_32}));
        } else if (same(t.payload, firmware())) {
            line.reply(i, registers_reply(t, {3, 0, 1, 884}));
        } else if (same(t.payload, status())) {
            line.reply(i, registers_reply(t, {position, state}));
        } else if (same(t.payload, di())) {
            line.reply(i, bits_reply(t, {true, false, false, false, false, false, true, false}));
        } else if (same(t.payload, dout())) {
            line.reply(i, bits_reply(t, {true, false, false, false, false, false, false, false}));
        }
    }
}

/// The FC16 a client's FC06 to @p address becomes.
inline fe::Payload fc16(std::uint16_t address, std::vector<std::uint16_t> values) {
    return modbus(fp::WriteMultipleRegistersRequest{address, std::move(values)});
}

}  // namespace fbt::xeg
