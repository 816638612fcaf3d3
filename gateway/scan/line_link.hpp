#pragma once
/// @file line_link.hpp
/// One request at a time on a serial port, synchronously: the scan's shell around the
/// engine's sans-I/O line core (engine/line_core.hpp), so a probe obeys the same line
/// timing and drive loop as the gateway (t3.5 silence, turnaround, local echo,
/// replies framed by their predicted length, timers as backstops). It waits with
/// ppoll() on the port's descriptor and reads the monotonic clock; there is no event
/// loop because a scan is a one-shot tool with the port to itself.

#include <array>
#include <cstdint>
#include <optional>

#include "engine/line_core.hpp"
#include "engine/line_delivery.hpp"
#include "engine/serial_port.hpp"
#include "engine/transaction.hpp"
#include "protocol/bytes.hpp"

namespace fieldbridge::scan {

class LineLink {
public:
    /// @p port must be open; it is used, not owned, and must outlive the link.
    /// Throws core::InvalidArgument for an impossible character format.
    LineLink(engine::SerialPort& port, engine::LineTimingConfig timing, engine::LogSink log = {});

    /// Sends @p payload to bus address @p address and waits for the outcome: ok with
    /// the reply, or timeout. Every byte received meanwhile is appended to @p received
    /// when given (the master keeps only the reply: a query several devices answer
    /// needs the rest). Throws engine::SerialPortError when the port fails.
    [[nodiscard]] engine::Outcome transact(engine::Payload payload, std::uint8_t address,
                                           protocol::Bytes* received = nullptr);

    /// Everything received until @p quiet passes without a byte (at most
    /// @p quiet + @p limit in all): further answers to a query every device answers.
    /// The bytes count as wire activity for the next request's silence.
    [[nodiscard]] protocol::Bytes listen(engine::Duration quiet, engine::Duration limit);

    [[nodiscard]] const engine::LineMaster& master() const noexcept { return core_.master(); }

private:
    /// Carries out @p event's steps until the core asks nothing; bytes read go to the
    /// core and to sink_ when set.
    void feed(engine::LineEvent&& event);
    void apply(const engine::LineStep& step);
    [[nodiscard]] engine::LineEvent read();
    [[nodiscard]] engine::LineEvent write(protocol::ByteView bytes);
    /// Feeds the next event: a Drive the core asked for, Writable once the driver
    /// takes bytes again, else Readable or the earlier wake timer's TimerFired;
    /// nothing to wait for is a logic error.
    void wait_for_event();

    engine::SerialPort& port_;
    engine::LineCore core_;
    engine::LineDelivery delivery_;
    std::optional<engine::TimePoint> exact_at_;
    std::optional<engine::TimePoint> lazy_at_;
    bool watch_writable_ = false;
    bool pending_drive_ = false;  ///< the core asked for a Drive: the next thing to feed
    protocol::Bytes* sink_ = nullptr;
    std::array<std::uint8_t, 256> buffer_{};
};

}  // namespace fieldbridge::scan
