// DeviceAgent: lifetime, health, follow-up reads, notices and logging. Polls are in
// device_agent_polls.cpp, northbound requests in device_agent_requests.cpp.
#include "engine/device_agent.hpp"

#include <stdexcept>
#include <utility>

#include "core/error.hpp"
#include "engine/device_agent_answers.hpp"
#include "engine/device_agent_impl.hpp"

namespace fieldbridge::engine {

namespace {

[[nodiscard]] std::unique_ptr<DeviceProfile> checked(std::unique_ptr<DeviceProfile> profile,
                                                     const DeviceAgentConfig& config) {
    if (!profile) {
        throw core::InvalidArgument("device agent '" + config.name + "' on line '" + config.line_name +
                                    "': no device profile was given; build one with make_profile()");
    }
    return profile;
}

}  // namespace

// ---- DeviceAgent: forwards to Impl ------------------------------------------------

DeviceAgent::DeviceAgent(asio::io_context& io, DeviceAgentConfig config, std::unique_ptr<DeviceProfile> profile,
                         SubmitFunction submit, LogSink log)
    : impl_(std::make_shared<Impl>(io, std::move(config), std::move(profile), std::move(submit), std::move(log))) {}

DeviceAgent::~DeviceAgent() {
    // A transaction callback running right now may still hold the Impl; everything
    // it could do after this line is answered or cancelled here.
    impl_->shut_down();
}

void DeviceAgent::start() { impl_->start(); }
void DeviceAgent::stop() { impl_->stop(); }
void DeviceAgent::request(const protocol::Request& request, ResponseHandler done) {
    impl_->request(request, std::move(done));
}
void DeviceAgent::broadcast_written(const protocol::Request& request) { impl_->broadcast_written(request); }
void DeviceAgent::retune(const DeviceAgentConfig& config) { impl_->retune(config); }
void DeviceAgent::on_health(bool online, TimePoint now) { impl_->on_health(online, now); }
void DeviceAgent::set_notice_callback(NoticeCallback callback) { impl_->set_notice_callback(std::move(callback)); }
RegisterImage& DeviceAgent::image() noexcept { return impl_->image(); }
const RegisterImage& DeviceAgent::image() const noexcept { return impl_->image(); }
const DeviceProfile& DeviceAgent::profile() const noexcept { return impl_->profile(); }
const DeviceAgentConfig& DeviceAgent::config() const noexcept { return impl_->config(); }
bool DeviceAgent::online() const noexcept { return impl_->online(); }
std::size_t DeviceAgent::poll_items() const noexcept { return impl_->poll_items(); }
bool DeviceAgent::motion_polling() const noexcept { return impl_->motion_polling(); }
std::size_t DeviceAgent::requests_in_progress() const noexcept { return impl_->requests_in_progress(); }

// ---- Impl: lifetime and health ---------------------------------------------------

DeviceAgent::Impl::Impl(asio::io_context& io, DeviceAgentConfig config, std::unique_ptr<DeviceProfile> profile,
                        SubmitFunction submit, LogSink log)
    : io_(io),
      config_(std::move(config)),
      profile_(checked(std::move(profile), config_)),
      submit_(std::move(submit)),
      log_(std::move(log)),
      polls_(profile_->poll_plan(), config_.motion_period, config_.startup_retry),
      poll_timer_(io) {
    if (!submit_) {
        throw core::InvalidArgument("device agent " + who() +
                                    ": no submit function; pass the line worker's submit()");
    }
}

DeviceAgent::Impl::~Impl() { shut_down(); }

void DeviceAgent::Impl::start() {
    if (state_ != State::idle) {
        return;
    }
    state_ = State::running;
    if (config_.polling) {
        polls_.restart(Clock::now());
        // Through the timer, not from here: the caller finishes its set-up first.
        arm_poll_timer();
    }
}

void DeviceAgent::Impl::stop() {
    state_ = State::stopped;
    poll_timer_.cancel();
    armed_for_.reset();
}

void DeviceAgent::Impl::shut_down() {
    stop();
    const std::vector<OperationPtr> pending = std::move(operations_);
    operations_.clear();
    for (const OperationPtr& op : pending) {
        answer(op, exception_response(op->request, refusal_for(OutcomeStatus::cancelled)));
    }
}

void DeviceAgent::Impl::on_health(bool online, TimePoint now) {
    if (online == online_) {
        return;
    }
    online_ = online;
    // Offline: every value is kept but reported offline; back online: stale until
    // read again (RegisterImage::set_offline).
    image_.set_offline(!online);
    log(LogLevel::info, who() + (online ? " is online again: polling everything" : " is offline"));
    if (!online) {
        // A device that does not answer is not moving as far as anyone can tell; the
        // line's back-off decides how often it is probed.
        polls_.set_motion(false);
        return;
    }
    if (state_ == State::running && config_.polling) {
        // It may have been power-cycled or replaced: read the startup items again.
        polls_.restart(now);
        arm_poll_timer();
    }
}

// ---- Impl: shared by polls and requests ------------------------------------------

Transaction DeviceAgent::Impl::transaction(Payload payload, Priority priority) const {
    Transaction t;
    t.device = config_.index;
    t.address = config_.address.value;  // the line's Transaction carries the byte
    t.payload = std::move(payload);
    t.priority = priority;
    return t;
}

void DeviceAgent::Impl::handle_extras(const ApplyResult& result, bool allow_follow_up) {
    if (result.notice) {
        log(LogLevel::warning, who() + ": " + result.notice->text);
        if (notice_) {
            notice_(*result.notice);
        }
    }
    if (result.follow_up && allow_follow_up) {
        submit_follow_up(*result.follow_up);
    }
}

void DeviceAgent::Impl::submit_follow_up(Payload payload) {
    if (state_ == State::stopped) {
        return;
    }
    if (follow_up_outstanding_) {
        // The one on its way will tell the same story (XEG FC07 after exception 0x04).
        log(LogLevel::debug, who() + ": follow-up read already on its way; not sending another");
        return;
    }
    Transaction t = transaction(payload, Priority::on_demand);
    t.retry_allowed = true;
    t.deadline = Clock::now() + config_.command_ttl;
    t.on_done = [weak = weak_from_this(), sent = std::move(payload)](const Outcome& outcome) {
        const auto self = weak.lock();
        if (!self) {
            return;
        }
        self->follow_up_outstanding_ = false;
        if (outcome.status != OutcomeStatus::ok) {
            self->log(LogLevel::debug, self->who() + ": follow-up read failed: " + to_string(outcome.status));
            return;
        }
        const TimePoint now = outcome_time(outcome);
        const ApplyResult result = self->profile_->apply(sent, outcome.reply, self->image_, now);
        // A follow-up never asks for another: FC07 answered with 0x04 would loop.
        self->handle_extras(result, false);
        self->update_motion(std::nullopt);
        self->arm_poll_timer();
    };
    follow_up_outstanding_ = true;
    submit_(std::move(t));
}

TimePoint DeviceAgent::Impl::outcome_time(const Outcome& outcome) {
    return outcome.finished != TimePoint{} ? outcome.finished : Clock::now();
}

void DeviceAgent::Impl::log(LogLevel level, std::string_view message) const { log_(level, message); }

std::string DeviceAgent::Impl::who() const {
    return "device '" + config_.name + "' (line '" + config_.line_name + "', address " +
           std::to_string(config_.address.value) + ")";
}

}  // namespace fieldbridge::engine
