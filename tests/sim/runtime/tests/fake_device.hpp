#pragma once
// A scripted BusDevice for the runtime's unit tests: answers frames addressed to it
// with a fixed reply and records what it saw.
#include <optional>
#include <string>
#include <vector>

#include "models/bus_device.hpp"
#include "protocol/rtu_frame.hpp"
#include "protocol/wtec_ascii_frame.hpp"

namespace fieldbridge::sim::runtime::test {

class FakeDevice final : public BusDevice {
public:
    FakeDevice(BusProtocol protocol, std::uint8_t address, protocol::Bytes reply,
               bool answers_broadcast = false)
        : protocol_(protocol), address_(address), reply_(std::move(reply)),
          answers_broadcast_(answers_broadcast) {}

    [[nodiscard]] BusProtocol protocol() const noexcept override { return protocol_; }
    [[nodiscard]] std::uint8_t address() const noexcept override { return address_; }
    [[nodiscard]] std::string_view type() const noexcept override { return "fake"; }

    [[nodiscard]] std::optional<protocol::Bytes> on_frame(protocol::ByteView frame,
                                                          Clock::time_point) override {
        frames.emplace_back(frame.begin(), frame.end());
        const std::uint8_t to = protocol_ == BusProtocol::modbus_rtu ? frame[0] : ascii_address(frame);
        if (to == address_ || (answers_broadcast_ && to == 0)) {
            return reply_;
        }
        return std::nullopt;
    }
    void advance(Clock::time_point) override { ++advances; }
    [[nodiscard]] std::string control(std::string_view command, Clock::time_point) override {
        controls.emplace_back(command);
        return command == "bad" ? "bad command" : "";
    }

    std::vector<protocol::Bytes> frames;
    std::vector<std::string> controls;
    int advances = 0;

private:
    static std::uint8_t ascii_address(protocol::ByteView frame) {
        const auto digit = [](std::uint8_t c) {
            return static_cast<std::uint8_t>(c <= '9' ? c - '0' : (c | 0x20) - 'a' + 10);
        };
        return static_cast<std::uint8_t>((digit(frame[1]) << 4) | digit(frame[2]));
    }

    BusProtocol protocol_;
    std::uint8_t address_;
    protocol::Bytes reply_;
    bool answers_broadcast_;
};

inline protocol::Bytes ascii(std::string_view text) {
    return protocol::Bytes(text.begin(), text.end());
}

}  // namespace fieldbridge::sim::runtime::test
