#pragma once
/// @file device_agent.hpp
/// One device on a line: its profile, its register image, its poll plan, and the
/// translation of northbound requests into transactions (spec §3, §4, §5).
///
///  - Polls: every item of the profile's poll plan is submitted at its period
///    (Priority::poll, poll_period set, reads retry_allowed); a poll is not submitted
///    again while the previous one of the same item is queued or in flight. While the
///    profile says in_motion(), items flagged motion are polled at the motion period
///    (rule 5); a motion command starts that at once. A block answered with exception
///    0x02 is split (PollPlan::on_block_rejected) and the log says so once.
///  - Northbound requests (Modbus TCP, MQTT commands): validate() -> a local exception;
///    reads served from the image when every register is fresh within max_age;
///    otherwise to_line() payloads are submitted one after another (Priority::command
///    for writes with deadline now + command_ttl and delay_before_command, urgent for
///    stops; Priority::on_demand for reads with retry_allowed), each reply applied to
///    the image, and respond() builds the answer. Outcomes that are not replies map to
///    Modbus exceptions: timeout / device_offline / line_down -> 0x0B (gateway target
///    failed to respond), expired / queue_full -> 0x06 (server busy), cancelled /
///    invalid_request -> 0x04 (server failure). spec §4 is the contract.
///  - A reply's follow_up (XEG exception 0x04 -> FC07) is submitted as an on-demand
///    read; a DeviceNotice is logged and reported to the notice callback.
///  - Health: on_health(false) marks the image offline; on_health(true) marks it stale
///    until read again.
///
/// Loop thread only. The agent does not own the line: it submits through a function.
#include <asio/io_context.hpp>
#include <functional>
#include <memory>
#include <string>

#include "engine/line_log.hpp"
#include "engine/profiles/device_profile.hpp"
#include "engine/register_image.hpp"
#include "engine/transaction.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::engine {

struct DeviceAgentConfig {
    std::string name;             ///< the device's config name, for logs and MQTT
    std::string line_name;
    DeviceIndex index = 0;        ///< its index on the line's scheduler
    std::uint8_t address = 1;     ///< bus address
    Duration max_age = std::chrono::milliseconds{0};          ///< 0: never serve reads from the image
    Duration command_ttl = std::chrono::milliseconds{500};    ///< deadline of commands
    Duration delay_before_command{};                          ///< rule 11
    bool polling = true;          ///< false: no polls (tests, scan)
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

    /// Starts polling. stop() cancels the poll timers; replies that arrive later are
    /// still applied to the image but nothing new is submitted. Idempotent.
    void start();
    void stop();

    /// A northbound request (PDU decoded): @p done is called exactly once, on the loop
    /// thread, never from inside request(), with the response (normal or exception).
    void request(const protocol::Request& request, ResponseHandler done);

    /// From the line's health callback (LineScheduler) or line state (down = offline).
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

private:
    class Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace fieldbridge::engine
