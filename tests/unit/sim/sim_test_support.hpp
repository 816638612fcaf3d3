#pragma once
// Helpers for the device model tests: hex literals, RTU / ASCII frames, a simulated
// clock, and one-line request/response checks that print frames in hex.

#include <chrono>
#include <optional>
#include <string>
#include <string_view>

#include "models/bus_device.hpp"
#include "protocol/bytes.hpp"

namespace fieldbridge::test {

using sim::Clock;

/// "02 10 06 00" (spaces optional) -> bytes.
[[nodiscard]] protocol::Bytes hex(std::string_view text);
/// Bytes -> "02 10 06 00".
[[nodiscard]] std::string hex_of(protocol::ByteView bytes);
/// An RTU ADU from its address and PDU in hex, CRC appended.
[[nodiscard]] protocol::Bytes rtu(std::string_view address_and_pdu_hex);
/// A WTEC ASCII frame body as the manual prints it ('>' ... CRC) -> wire bytes with CR LF.
[[nodiscard]] protocol::Bytes ascii(std::string_view body);
/// Wire bytes of an ASCII frame -> text without CR LF, for messages and comparisons.
[[nodiscard]] std::string ascii_text(protocol::ByteView bytes);

/// A simulated clock for the models: starts at an arbitrary epoch, moves only when told.
class SimClock {
public:
    [[nodiscard]] Clock::time_point now() const noexcept { return now_; }
    void advance(Clock::duration d) noexcept { now_ += d; }
    void advance_ms(long long ms) noexcept { now_ += std::chrono::milliseconds(ms); }
    void advance_s(long long s) noexcept { now_ += std::chrono::seconds(s); }

private:
    Clock::time_point now_ = Clock::time_point{} + std::chrono::hours(1000);
};

/// Sends @p request to @p device and returns the reply as hex ("" when there is none).
[[nodiscard]] std::string exchange(sim::BusDevice& device, const protocol::Bytes& request,
                                   Clock::time_point now);
/// Same for ASCII: the reply body without CR LF ("" when there is none).
[[nodiscard]] std::string exchange_ascii(sim::BusDevice& device, std::string_view body,
                                         Clock::time_point now);

/// Reads @p count registers with FC03/FC04 from @p address and returns the values;
/// fails the test when the reply is not a normal read reply.
[[nodiscard]] std::vector<std::uint16_t> read_registers(sim::BusDevice& device, std::uint8_t unit,
                                                        std::uint8_t function, std::uint16_t address,
                                                        std::uint16_t count, Clock::time_point now);
/// Writes registers with FC16 (or FC06 for @p single) and returns the reply PDU as hex.
[[nodiscard]] std::string write_registers(sim::BusDevice& device, std::uint8_t unit,
                                          std::uint16_t address, std::vector<std::uint16_t> values,
                                          Clock::time_point now, bool single = false);

}  // namespace fieldbridge::test
