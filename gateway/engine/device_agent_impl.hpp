#pragma once
/// @file device_agent_impl.hpp
/// The inside of DeviceAgent (private to gateway/engine): its state and the three
/// duties it splits into, one file each: device_agent.cpp (lifetime, health,
/// follow-ups, logging), device_agent_polls.cpp (the poll timer and poll replies),
/// device_agent_requests.cpp (northbound requests).
///
/// Every transaction callback and timer handler holds a weak_ptr to the Impl and
/// does nothing once it has expired: the line may complete a transaction long after
/// the agent is gone.

#include <asio/steady_timer.hpp>
#include <cstdint>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "engine/device_agent.hpp"
#include "engine/poll_schedule.hpp"

namespace fieldbridge::engine {

class DeviceAgent::Impl : public std::enable_shared_from_this<Impl> {
public:
    Impl(asio::io_context& io, DeviceAgentConfig config, std::unique_ptr<DeviceProfile> profile,
         SubmitFunction submit, LogSink log);
    ~Impl();
    Impl(const Impl&) = delete;
    Impl& operator=(const Impl&) = delete;

    void start();
    void stop();
    /// stop(), then every unfinished request is answered 0x04 (the destructor of
    /// DeviceAgent calls it: callbacks may keep the Impl alive a little longer).
    void shut_down();
    void request(const protocol::Request& request, ResponseHandler done);
    void broadcast_written(const protocol::Request& request);
    void on_health(bool online, TimePoint now);
    void set_notice_callback(NoticeCallback callback) { notice_ = std::move(callback); }
    void retune(const DeviceAgentConfig& config) {
        config_.max_age = config.max_age;
        config_.command_ttl = config.command_ttl;
        config_.delay_before_command = config.delay_before_command;
    }

    RegisterImage& image() noexcept { return image_; }
    [[nodiscard]] const RegisterImage& image() const noexcept { return image_; }
    [[nodiscard]] const DeviceProfile& profile() const noexcept { return *profile_; }
    [[nodiscard]] const DeviceAgentConfig& config() const noexcept { return config_; }
    [[nodiscard]] bool online() const noexcept { return online_; }
    [[nodiscard]] std::size_t poll_items() const noexcept { return polls_.plan().items().size(); }
    [[nodiscard]] bool motion_polling() const noexcept { return polls_.motion(); }
    [[nodiscard]] std::size_t requests_in_progress() const noexcept { return operations_.size(); }

private:
    enum class State : std::uint8_t { idle, running, stopped };

    /// A northbound request on its way through the line.
    struct Operation {
        protocol::Request request;
        ResponseHandler done;
        Classification classification;
        std::vector<Payload> payloads;
        std::vector<Reply> replies;  ///< one per payload answered so far
        bool answered = false;
    };
    using OperationPtr = std::shared_ptr<Operation>;

    // ---- device_agent_polls.cpp ----
    void arm_poll_timer();
    void on_poll_timer();
    void submit_due_polls();
    void on_poll_done(std::uint32_t id, const Outcome& outcome);
    void on_block_rejected(std::uint32_t id, TimePoint now);
    void warn_poll_once(std::uint32_t id, std::string_view what);
    /// Rule 5 after an image update: motion on while the device moves; off once a
    /// motion poll sent after the last motion command shows it at rest.
    void update_motion(std::optional<std::uint32_t> motion_poll);
    void start_motion(std::string_view why);

    // ---- device_agent_requests.cpp ----
    void submit_step(const OperationPtr& op);
    void on_step_done(const OperationPtr& op, const Outcome& outcome);
    /// How answer() hands a response over: posted to the loop, or (from a line
    /// completion, never inside request()) called at once.
    enum class Delivery { posted, now };
    void answer(const OperationPtr& op, protocol::Response response, Delivery delivery = Delivery::posted);
    /// The motion poll items' registers go to the line until the next motion poll.
    void mark_motion_status_stale();
    void post_answer(ResponseHandler done, protocol::Response response);

    // ---- device_agent.cpp ----
    /// The base of every transaction of this device.
    [[nodiscard]] Transaction transaction(Payload payload, Priority priority) const;
    /// What every reply may carry besides its data: a follow-up read and a notice.
    void handle_extras(const ApplyResult& result, bool allow_follow_up);
    void submit_follow_up(Payload payload);
    /// When the outcome was decided (the line's clock), or now when it does not say.
    [[nodiscard]] static TimePoint outcome_time(const Outcome& outcome);
    void log(LogLevel level, std::string_view message) const;
    [[nodiscard]] std::string who() const;

    asio::io_context& io_;
    DeviceAgentConfig config_;
    std::unique_ptr<DeviceProfile> profile_;
    SubmitFunction submit_;
    LogSink log_;
    NoticeCallback notice_;
    RegisterImage image_;
    PollSchedule polls_;
    asio::steady_timer poll_timer_;
    std::optional<TimePoint> armed_for_;  ///< the poll timer waits for this due time
    State state_ = State::idle;
    bool online_ = true;
    bool follow_up_outstanding_ = false;
    unsigned motion_commands_ = 0;       ///< motion commands submitted, not finished
    TimePoint motion_command_done_{};    ///< when the last one finished
    std::set<std::uint32_t> warned_items_;  ///< poll items whose failure was logged
    std::vector<OperationPtr> operations_;  ///< requests not answered yet
    unsigned in_request_ = 0;               ///< request() calls on the stack
};

}  // namespace fieldbridge::engine
