#pragma once
/// @file serial_device_target.hpp
/// A serial device as a Modbus TCP unit (spec §4): the request PDU is decoded and
/// handed to the device's agent, which answers from the register image or through
/// the line's scheduler (validation, command lane, deadline, exception mapping:
/// device_agent.hpp). Here only what the agent cannot know:
///  - a PDU that does not decode: exception 0x03 (0x01 for a function code the
///    codecs reject outright), nothing sent;
///  - the line is down (port closed or gone): exception 0x0A, nothing queued.
#include <asio/io_context.hpp>
#include <cstdint>
#include <memory>

#include "engine/device_agent.hpp"
#include "engine/line_worker.hpp"
#include "northbound/unit_target.hpp"

namespace fieldbridge::northbound {

class SerialDeviceTarget final : public UnitTarget {
public:
    /// Both must outlive the target (the engine owns them; the daemon removes the
    /// routes before rebuilding the engine).
    SerialDeviceTarget(asio::io_context& io, engine::DeviceAgent& agent, const engine::LineWorker& line);

    using UnitTarget::handle;
    void handle(core::UnitId unit, const RequestPdu& request, const ClientRef& client, PduHandler done) override;

private:
    void answer(PduHandler done, protocol::Bytes pdu);

    asio::io_context& io_;
    engine::DeviceAgent& agent_;
    const engine::LineWorker& line_;
};

}  // namespace fieldbridge::northbound
