#pragma once
/// @file upstream_target.hpp
/// The Huacheng R6 pass-through (spec §4, §5; docs/r6-passthrough.md): the unit IDs
/// of one upstream Modbus TCP server, served over one managed connection.
///
/// - handle(): the PDU is forwarded unchanged to the upstream unit mapped from the
///   gateway unit, with an upstream transaction ID of our own (the server restores
///   the client's); the reply PDU comes back unchanged. Exceptions made here:
///   0x0A unknown unit / upstream not connected / target stopped (never sent),
///   0x0B no reply within response_timeout, the connection dropped while the request
///   was out, or a command that waited past command_ttl (never sent), 0x06 queue full,
///   0x01 / 0x03 a PDU no function code can carry (never sent), 0x04 a reply that
///   does not fit its request (exception length, byte count, quantity, write echo:
///   protocol::decode_response), counted and logged, never passed on.
/// - queue discipline and stateful sequences: UpstreamScheduler.
/// - state polling: every poll_period each unit's R6 state (r6_state.hpp) is read at
///   poll priority into a register image and decoded; a callback reports changes.
///
/// Loop thread only. Every handler gets exactly one answer, posted to the loop (never
/// from inside handle()), except the requests of a client that closed. stop() answers
/// what is outstanding with 0x0A (posted); the target may be destroyed with requests
/// outstanding and handlers still queued in the io_context.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <asio/io_context.hpp>

#include "config/config.hpp"
#include "core/modbus_ids.hpp"
#include "engine/line_log.hpp"
#include "engine/profiles/device_profile.hpp"
#include "engine/register_image.hpp"
#include "northbound/unit_target.hpp"
#include "northbound/upstream/upstream_link.hpp"

namespace fieldbridge::northbound::upstream {

/// What the configuration does not set (docs/r6-passthrough.md explains the defaults).
struct UpstreamTuning {
    /// Requests outstanding on the connection at once. 1: the controller sees one
    /// request at a time, as from a single master; raise it only for servers known to
    /// queue pipelined requests.
    std::size_t window = 1;
    /// A stateful sequence (counter read, data-source view or upload) lapses when its
    /// owner leaves it idle this long.
    engine::Duration sequence_hold = std::chrono::seconds{2};
    /// Consecutive response timeouts after which the connection is re-established
    /// (a half-open TCP connection answers nothing).
    unsigned reconnect_after_timeouts = 3;
};

/// The decoded state of one R6 unit, for MQTT.
struct R6State {
    core::UnitId unit_id;      ///< the gateway unit
    std::string name;          ///< the unit's MQTT device name
    bool online = false;       ///< the connection is up and the last poll cycle was answered
    engine::DecodedState state;
    std::vector<engine::Alarm> alarms;
    engine::TimePoint updated{};  ///< end of the poll cycle that produced it
};
/// Called on the loop thread when a unit's decoded state, alarms or online flag change.
using R6StateCallback = std::function<void(const R6State&)>;

struct UpstreamStats {
    std::uint64_t requests = 0;      ///< client requests handled
    std::uint64_t forwarded = 0;     ///< frames sent upstream (polls included)
    std::uint64_t replies = 0;       ///< replies matched to a request
    std::uint64_t late_replies = 0;  ///< replies nobody waited for any more
    std::uint64_t malformed_replies = 0;  ///< replies that did not fit their request: answered 0x04
    std::uint64_t timeouts = 0;
    std::uint64_t expired = 0;
    std::uint64_t queue_full = 0;
    std::uint64_t path_down = 0;
    std::uint64_t connects = 0;
    std::uint64_t poll_cycles = 0;   ///< completed
};

class UpstreamTarget final : public UnitTarget {
public:
    UpstreamTarget(asio::io_context& io, config::UpstreamConfig config, engine::LogSink log,
                   UpstreamTuning tuning = {});
    ~UpstreamTarget() override;

    /// Connects (in the background) and starts polling. Returns at once.
    void start();
    /// Closes the connection, answers everything outstanding 0x0A. Idempotent.
    void stop();

    using UnitTarget::handle;
    void handle(core::UnitId unit, const RequestPdu& request, const ClientRef& client, PduHandler done) override;
    void client_closed(std::uint64_t connection) override;

    void set_state_callback(R6StateCallback callback);
    /// The last decoded state of gateway unit @p unit; nullopt for a unit not mapped here.
    [[nodiscard]] std::optional<R6State> state(core::UnitId unit) const;
    /// The register image of gateway unit @p unit (nullptr when not mapped here).
    [[nodiscard]] const engine::RegisterImage* image(core::UnitId unit) const;

    [[nodiscard]] LinkState link_state() const noexcept;
    [[nodiscard]] UpstreamStats stats() const noexcept;
    [[nodiscard]] const config::UpstreamConfig& config() const noexcept;

    class Impl;

private:
    std::shared_ptr<Impl> impl_;
};

}  // namespace fieldbridge::northbound::upstream
