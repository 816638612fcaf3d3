#pragma once
/// @file device_agent.hpp
/// One device on a line: its profile, its register image, its poll plan, and the
/// translation of northbound requests into transactions (spec §3, §4, §5).
///
///  - Polls: every item of the profile's poll plan is submitted at its period
///    (Priority::poll, poll_period set, reads retry_allowed) on a fixed cadence; items
///    due together are submitted together; a poll is not submitted again while the
///    previous one of the same item is queued or in flight (poll_schedule.hpp).
///    Startup items go once at start() and again when the device comes back online,
///    retried `startup_retry` after a failure. While the profile says in_motion(),
///    items flagged motion are polled at `motion_period` (rule 5); a motion command
///    starts that at once, and it ends at the first motion poll sent after the last
///    motion command finished that shows the device at rest. A poll that times out
///    marks what it fills stale. A block answered with exception 0x02 is split
///    (PollPlan::on_block_rejected) and the log says so once.
///  - Northbound requests (Modbus TCP, MQTT commands): validate() -> a local exception;
///    reads served from the image when every register is fresh within max_age;
///    otherwise to_line() payloads are submitted one after another (Priority::command
///    for writes with deadline now + command_ttl and delay_before_command, urgent for
///    stops; Priority::on_demand for reads with retry_allowed and the same deadline,
///    so a client never waits forever), each reply applied to the image, and
///    respond() builds the answer. A sequence stops at the first payload that fails
///    or is answered with a device exception. Outcomes that are not replies map to
///    Modbus exceptions through the gateway's one mapping (refusal_for(),
///    protocol/gateway_exceptions.hpp; the table in docs/modbus-tcp.md): timeout /
///    device_offline / expired -> 0x0B, queue_full -> 0x06, line_down and cancelled
///    (also a sequence the agent's stop() or destruction cut short) -> 0x0A,
///    invalid_request, bad_reply (the device answered something that does not fit) -> 0x04.
///  - A reply's follow_up (XEG exception 0x04 -> FC07) is submitted as an on-demand
///    read (one at a time); a DeviceNotice is logged and reported to the notice
///    callback.
///  - Health: on_health(false) marks the image offline and ends motion polling;
///    on_health(true) marks it stale until read again and polls every item at once
///    (startup items included: the device may have been replaced).
///  - Lifetime: transactions complete through callbacks that hold only a weak
///    reference to the agent, so the line may complete them after the agent is gone.
///    Destroying the agent answers its unfinished requests 0x04 (posted).
///
/// Loop thread only. The agent does not own the line: it submits through a function,
/// which may complete a transaction inside the call. No I/O but one timer.
#include <asio/io_context.hpp>
#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "core/modbus_ids.hpp"
#include "engine/line_log.hpp"
#include "engine/profiles/device_profile.hpp"
#include "engine/register_image.hpp"
#include "engine/transaction.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::engine {

struct DeviceAgentConfig {
    std::string name;             ///< the device's config name, for logs and MQTT
    /// The `type:` as configured (a built-in type or a device definition's name); ""
    /// in tests: the profile's type then.
    std::string type_name;
    std::string line_name;
    DeviceIndex index = 0;        ///< its index on the line's scheduler
    core::BusAddress address{1};
    Duration max_age = std::chrono::milliseconds{0};          ///< 0: never serve reads from the image
    Duration command_ttl = std::chrono::milliseconds{500};    ///< deadline of commands
    Duration delay_before_command{};                          ///< rule 11
    bool polling = true;          ///< false: no polls (tests, scan)
    /// Rule 5: the period of motion-flagged items while the device moves (the
    /// profile's PollPeriods::motion; the profile interface does not expose it).
    Duration motion_period = std::chrono::milliseconds{20};
    /// A startup item (model, firmware) that failed is tried again after this.
    Duration startup_retry = std::chrono::seconds{1};
};

using SubmitFunction = std::function<void(Transaction)>;
using ResponseHandler = std::function<void(const protocol::Response&)>;
using NoticeCallback = std::function<void(const DeviceNotice&)>;

class DeviceAgent {
public:
    DeviceAgent(asio::io_context& io, DeviceAgentConfig config, std::unique_ptr<DeviceProfile> profile,
                SubmitFunction submit, LogSink log = {});
    ~DeviceAgent();
    DeviceAgent(const DeviceAgent&) = delete;
    DeviceAgent& operator=(const DeviceAgent&) = delete;

    /// Starts polling. stop() cancels the poll timer; replies that arrive later are
    /// still applied to the image but nothing new is submitted: a request arriving
    /// after stop() is answered 0x0A (gateway path unavailable), one whose next
    /// payload is due after stop() 0x04. Both idempotent; start() after stop() does
    /// nothing (a stopped agent is being replaced).
    void start();
    void stop();

    /// Reload: new freshness and command timing (max_age, command_ttl,
    /// delay_before_command of @p config; every other field must be unchanged) apply
    /// from the next request on; the image, the poll plan and requests in flight stay.
    void retune(const DeviceAgentConfig& config);

    /// A northbound request (PDU decoded): @p done is called exactly once, on the loop
    /// thread, never from inside request(), with the response (normal or exception).
    void request(const protocol::Request& request, ResponseHandler done);

    /// A broadcast write that went out on this device's line: no reply confirms it, so
    /// what it covers is no longer known to be current (a cached read goes to the
    /// line), and a motion command makes the motion status stale as a unicast one does.
    void broadcast_written(const protocol::Request& request);

    /// From the line's health callback (LineWorker) or line state (down = offline).
    void on_health(bool online, TimePoint now);
    void set_notice_callback(NoticeCallback callback);

    [[nodiscard]] RegisterImage& image() noexcept;
    [[nodiscard]] const RegisterImage& image() const noexcept;
    [[nodiscard]] const DeviceProfile& profile() const noexcept;
    [[nodiscard]] const DeviceAgentConfig& config() const noexcept;
    [[nodiscard]] bool online() const noexcept;
    /// Poll items currently planned (after splits) and whether motion polling is on.
    [[nodiscard]] std::size_t poll_items() const noexcept;
    [[nodiscard]] bool motion_polling() const noexcept;
    /// Client requests taken and not answered yet (a retired agent is kept until 0).
    [[nodiscard]] std::size_t requests_in_progress() const noexcept;

private:
    class Impl;
    // Shared so that transaction callbacks can hold a weak reference.
    std::shared_ptr<Impl> impl_;
};

}  // namespace fieldbridge::engine
