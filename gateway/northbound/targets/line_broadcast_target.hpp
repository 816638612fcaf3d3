#pragma once
/// @file line_broadcast_target.hpp
/// A line's broadcast unit (config `broadcast_unit`, spec §4): a write to it is sent
/// to every device of the line at once and answered at once (nobody answers a
/// broadcast on the bus, so there is nothing to wait for).
///
/// The bus address is 0 for Modbus devices and 0xFF for the EXCD203MB (seed 002 §5);
/// a line with both gets the write twice, once per address, so every device acts.
/// WTEC ASCII devices do not speak Modbus and ignore both. Only writes (FC05, 06,
/// 0F, 10) can be broadcast: anything else is exception 0x01. The writes go in the
/// command class with the line's shortest `command_ttl`, so a broadcast that cannot
/// start in time is dropped rather than sent late (rule 9); the client has its
/// answer already, which is the nature of a broadcast.
#include <asio/io_context.hpp>
#include <cstdint>
#include <vector>

#include "engine/line_worker.hpp"
#include "engine/transaction.hpp"
#include "northbound/unit_target.hpp"

namespace fieldbridge::northbound {

class LineBroadcastTarget final : public UnitTarget {
public:
    /// @p addresses: the bus broadcast addresses to send to (0 and/or 0xFF).
    LineBroadcastTarget(asio::io_context& io, engine::LineWorker& line, std::vector<std::uint8_t> addresses,
                        engine::Duration command_ttl);

    void handle(std::uint8_t unit, protocol::ByteView request_pdu, const ClientRef& client,
                PduHandler done) override;

private:
    asio::io_context& io_;
    engine::LineWorker& line_;
    std::vector<std::uint8_t> addresses_;
    engine::Duration command_ttl_;
};

}  // namespace fieldbridge::northbound
