#pragma once
/// @file line_link.hpp
/// One request at a time on a serial port, synchronously: the scan's own small
/// driver of the sans-I/O LineMaster (engine/line_master.hpp), so a probe obeys the
/// same line timing as the gateway (t3.5 silence, turnaround, local echo, replies
/// framed by their predicted length, timers as backstops). It waits with ppoll() on
/// the port's descriptor and reads the monotonic clock; there is no event loop
/// because a scan is a one-shot tool with the port to itself.

#include <cstdint>

#include "engine/line_master.hpp"
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

    [[nodiscard]] const engine::LineMaster& master() const noexcept { return master_; }

private:
    /// Waits until the port is readable or @p until; hands what arrived to the
    /// master (and appends it to @p sink when given).
    void wait_and_read(engine::TimePoint until, protocol::Bytes* sink);
    void write_all(protocol::ByteView bytes);

    engine::SerialPort& port_;
    engine::LineMaster master_;
    std::uint64_t next_id_ = 1;
};

}  // namespace fieldbridge::scan
