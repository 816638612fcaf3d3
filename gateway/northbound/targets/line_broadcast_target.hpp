#pragma once
/// @file line_broadcast_target.hpp
/// A line's broadcast unit (config `broadcast_unit`, spec §4; docs/modbus-tcp.md,
/// "Broadcast units"): a write to it is sent to every device of the line at once.
///
///  - Only writes (FC05, 06, 0F, 10) can be broadcast: anything else is 0x01; a PDU
///    that does not decode 0x03; the line down 0x0A.
///  - The write goes through the profile of every Modbus device of the line
///    (broadcast_plan.hpp: protected registers, ranges, 32-bit pairs, translations)
///    and, in the server, through the access rules of every unit of the line
///    (ruled_as()). A write the devices do not all take is refused, nothing sent.
///  - The bus address is 0 for Modbus devices and 0xFF for the EXCD203MB (seed 002
///    §5); a line with both gets the write once per address whose devices take it.
///  - The line's broadcast budget (`broadcast_share`, broadcast_budget.hpp): a
///    broadcast that would exceed it is refused with 0x06 before it is queued. Only
///    what went on the line is charged: a broadcast that is not sent after all gives
///    its share back.
///  - A stop (every step urgent, rule 4) is never refused and goes ahead of every
///    queued command, but stops have a budget of their own at the same share: a stop
///    over it is held (not refused) until the stops' budget allows it, and a held stop
///    identical to one already held rides with it (one frame, every client answered
///    when it was written). So the first stop goes out at once whatever ordinary
///    broadcasts spent, and a flood of stops takes at most the share of the line.
///  - The writes go in the command class with the line's shortest `command_ttl`, one
///    after another. The client is answered after the last one has been written and
///    the line has settled (nobody answers a broadcast, so "written" is all there is
///    to know); a write that could not be queued or started in time ends the
///    sequence with the exception of its outcome (0x06, 0x0B, 0x0A:
///    protocol/gateway_exceptions.hpp). No acknowledgement for a write not sent.
#include <asio/io_context.hpp>
#include <asio/steady_timer.hpp>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/modbus_ids.hpp"
#include "engine/device_agent.hpp"
#include "engine/line_worker.hpp"
#include "engine/transaction.hpp"
#include "northbound/targets/broadcast_budget.hpp"
#include "northbound/targets/broadcast_plan.hpp"
#include "northbound/unit_target.hpp"

namespace fieldbridge::northbound {

/// A device of the broadcast's line and its Modbus TCP unit.
struct LineUnit {
    engine::DeviceAgent* agent = nullptr;
    core::UnitId unit_id;
};

struct BroadcastSettings {
    engine::Duration command_ttl = std::chrono::milliseconds{500};  ///< the line's shortest
    unsigned share_percent = 10;                                     ///< config broadcast_share
};

class LineBroadcastTarget final : public UnitTarget {
public:
    /// @p devices: every device of the line, in configuration order. The line and the
    /// agents must outlive the target's handle() calls (the engine owns them; the
    /// daemon removes the routes before rebuilding the engine); writes in flight when
    /// the target goes are answered 0x0A.
    LineBroadcastTarget(asio::io_context& io, engine::LineWorker& line, std::vector<LineUnit> devices,
                        BroadcastSettings settings);
    ~LineBroadcastTarget() override;

    using UnitTarget::handle;
    void handle(core::UnitId unit, const RequestPdu& request, const ClientRef& client, PduHandler done) override;
    [[nodiscard]] std::span<const core::UnitId> ruled_as() const noexcept override { return units_; }

private:
    struct Shared;
    struct Operation;
    static void submit_step(const std::shared_ptr<Shared>& shared, const std::shared_ptr<Operation>& op);
    static void send_stop(const std::shared_ptr<Shared>& shared, const std::shared_ptr<Operation>& op);
    static void release_held_stops(const std::shared_ptr<Shared>& shared);
    static void arm_stop_timer(const std::shared_ptr<Shared>& shared);
    /// The line time each step holds (frame, silence, delay before, broadcast_delay).
    [[nodiscard]] std::vector<engine::Duration> line_time(const std::vector<BroadcastStep>& steps) const;

    std::shared_ptr<Shared> shared_;
    std::vector<LineUnit> devices_;
    std::vector<core::UnitId> units_;
};

}  // namespace fieldbridge::northbound
