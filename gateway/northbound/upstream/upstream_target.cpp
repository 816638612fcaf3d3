#include "northbound/upstream/upstream_target.hpp"

#include <algorithm>
#include <fmt/format.h>

#include <asio/post.hpp>
#include <asio/steady_timer.hpp>

#include "northbound/upstream/r6_state.hpp"
#include "northbound/upstream/request_class.hpp"
#include "northbound/upstream/upstream_scheduler.hpp"
#include "protocol/gateway_exceptions.hpp"
#include "protocol/mbap_frame.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::northbound::upstream {
namespace {

using engine::Clock;

using protocol::exception_pdu;
using protocol::GatewayRefusal;

/// spec §4 through the gateway's one mapping (protocol/gateway_exceptions.hpp):
/// 0x0A the path is unavailable (nothing was sent), 0x0B the target did not answer in
/// time (or the command's deadline passed), 0x06 the queue is full.
protocol::Bytes answer_pdu(core::FunctionCode function, const UpstreamOutcome& outcome) {
    switch (outcome.status) {
        case UpstreamStatus::ok: return outcome.response_pdu;
        case UpstreamStatus::timeout: return exception_pdu(function, GatewayRefusal::no_answer);
        case UpstreamStatus::expired: return exception_pdu(function, GatewayRefusal::expired);
        case UpstreamStatus::queue_full: return exception_pdu(function, GatewayRefusal::busy);
        case UpstreamStatus::cancelled: return exception_pdu(function, GatewayRefusal::cancelled);
        case UpstreamStatus::path_down: break;
    }
    return exception_pdu(function, GatewayRefusal::path_down);
}

SchedulerSettings scheduler_settings(const config::UpstreamConfig& c, const UpstreamTuning& t) {
    SchedulerSettings s;
    s.queue_limit = c.queue_limit;
    s.window = t.window;
    s.response_timeout = c.response_timeout;
    s.command_ttl = c.command_ttl;
    s.poll_period = c.poll_period;
    s.sequence_hold = t.sequence_hold;
    s.sequence_max_hold = c.sequence_max_hold;
    return s;
}

LinkSettings link_settings(const config::UpstreamConfig& c) {
    return {c.name, c.host, c.port, c.connect_timeout, c.reconnect_backoff.initial, c.reconnect_backoff.max};
}

}  // namespace

class UpstreamTarget::Impl : public std::enable_shared_from_this<UpstreamTarget::Impl> {
public:
    Impl(asio::io_context& io, config::UpstreamConfig config, engine::LogSink log, UpstreamTuning tuning)
        : io_(io), config_(std::move(config)), tuning_(tuning), log_(std::move(log)),
          scheduler_(scheduler_settings(config_, tuning_), log_), tick_timer_(io), poll_timer_(io) {
        for (const auto& u : config_.units) {
            auto unit = std::make_unique<Unit>();
            unit->config = u;
            unit->state.unit_id = u.unit_id;
            unit->state.name = u.name;
            units_.push_back(std::move(unit));
        }
    }

    /// The link's events reach the Impl through a weak reference: the link's
    /// internals may outlive it in queued handlers.
    void create_link() {
        std::weak_ptr<Impl> weak = weak_from_this();
        LinkEvents events;
        events.state_changed = [weak](LinkState state) {
            if (auto self = weak.lock()) self->on_link_state(state);
        };
        events.frame = [weak](protocol::MbapFrame frame) {
            if (auto self = weak.lock()) self->on_frame(std::move(frame));
        };
        link_ = std::make_unique<UpstreamLink>(io_, link_settings(config_), log_, std::move(events));
    }

    void start() {
        if (started_) return;
        started_ = true;
        stopped_ = false;
        link_->start();
    }

    void stop() {
        if (stopped_) return;
        stopped_ = true;
        started_ = false;
        link_->stop();
        tick_timer_.cancel();
        poll_timer_.cancel();
        scheduler_.fail_all(UpstreamStatus::cancelled, UpstreamStatus::cancelled);
        post_completions();
        for (auto& unit : units_) {
            abandon_cycle(*unit);
            set_online(*unit, false, Clock::now());
        }
    }

    void handle(core::UnitId unit_id, const RequestPdu& request, const ClientRef& client, PduHandler done) {
        ++stats_.requests;
        const protocol::ByteView pdu = request.bytes;
        const core::FunctionCode function = request.function();
        const Unit* unit = find(unit_id);
        if (unit == nullptr || !started_) {
            answer_later(std::move(done), exception_pdu(function, GatewayRefusal::path_down));
            return;
        }
        const Classified classified = classify(request.decoded, pdu);
        if (!classified.request) {
            answer_later(std::move(done), exception_pdu(function, classified.local.refusal));
            return;
        }
        const LinkState link = link_->state();
        if (link != LinkState::up && link != LinkState::connecting) {
            ++stats_.path_down;
            answer_later(std::move(done), exception_pdu(function, GatewayRefusal::path_down));
            return;
        }
        // The client's request as decoded by the server, to check the reply against.
        std::optional<protocol::Request> asked;
        if (request.decoded.complete()) asked = request.decoded.value;
        UpstreamRequest upstream;
        upstream.client = client.connection;
        upstream.unit = unit->config.upstream_unit;
        upstream.pdu.assign(pdu.begin(), pdu.end());
        upstream.request_class = *classified.request;
        upstream.done = [weak = weak_from_this(), done = std::move(done), function, unit_id,
                         asked = std::move(asked)](const UpstreamOutcome& outcome) {
            const auto self = weak.lock();
            if (self && outcome.status == UpstreamStatus::ok) {
                if (self->reply_malformed(unit_id, asked, outcome.response_pdu)) {
                    done(exception_pdu(function, GatewayRefusal::gateway_failure));
                    return;
                }
            }
            done(answer_pdu(function, outcome));
        };
        scheduler_.submit(std::move(upstream), Clock::now());
        pump();
    }

    /// What is wrong with the upstream's reply to a client request (empty: nothing).
    /// A reply that does not fit its request (an exception of another length than 2,
    /// another quantity, a byte count its data does not match, another echo of a
    /// write) never reaches the client: it would read garbage as data.
    [[nodiscard]] bool reply_malformed(core::UnitId unit_id, const std::optional<protocol::Request>& asked,
                                       const protocol::Bytes& reply) {
        if (!asked) return false;  // the client's own business (it was forwarded as it came)
        const auto decoded = protocol::decode_response(reply, *asked);
        if (!decoded.malformed()) return false;
        ++stats_.malformed_replies;
        if (log_.enabled(engine::LogLevel::warning)) {
            log_(engine::LogLevel::warning,
                 fmt::format("upstream {}: unit {} sent a malformed reply to function 0x{:02X} ({}; {} bytes, "
                             "first 0x{:02X}); the client gets exception 0x04, nothing of it is passed on",
                             config_.name, unit_id.value, protocol::function_code(*asked).value,
                             protocol::to_string(decoded.error), reply.size(), protocol::pdu_function(reply).value));
        }
        return true;
    }

    void client_closed(std::uint64_t connection) {
        scheduler_.client_closed(connection);
        pump();
    }

    void set_state_callback(R6StateCallback callback) { state_callback_ = std::move(callback); }

    [[nodiscard]] const R6State* state(core::UnitId unit_id) const {
        const Unit* unit = find(unit_id);
        return unit == nullptr ? nullptr : &unit->state;
    }
    [[nodiscard]] const engine::RegisterImage* image(core::UnitId unit_id) const {
        const Unit* unit = find(unit_id);
        return unit == nullptr ? nullptr : &unit->image;
    }
    [[nodiscard]] LinkState link_state() const noexcept { return link_->state(); }
    [[nodiscard]] UpstreamStats stats() const noexcept {
        UpstreamStats s = stats_;
        s.connects = link_->connects();
        return s;
    }
    [[nodiscard]] const config::UpstreamConfig& config() const noexcept { return config_; }

private:
    struct Unit {
        config::UpstreamUnitConfig config;
        engine::RegisterImage image;
        R6State state;
        bool cycle_running = false;
        std::uint64_t cycle = 0;  ///< replies of an abandoned cycle carry an older number
        std::size_t step = 0;
        bool cycle_failed = false;
    };

    [[nodiscard]] Unit* find(core::UnitId unit_id) const {
        const auto it = std::find_if(units_.begin(), units_.end(),
                                     [unit_id](const auto& u) { return u->config.unit_id == unit_id; });
        return it == units_.end() ? nullptr : it->get();
    }

    void answer_later(PduHandler done, protocol::Bytes pdu) {
        asio::post(io_, [done = std::move(done), pdu = std::move(pdu)]() mutable { done(std::move(pdu)); });
    }

    /// Sends what may go now, hands the outcomes to the loop, re-arms the deadline timer.
    void pump() {
        const auto now = Clock::now();
        if (link_->state() == LinkState::up) {
            while (auto dispatch = scheduler_.next(now)) {
                ++stats_.forwarded;
                link_->send(protocol::encode_mbap(dispatch->transaction_id, dispatch->unit, dispatch->pdu));
            }
        } else {
            scheduler_.tick(now);  // commands still expire while connecting
        }
        post_completions();
        if (tuning_.reconnect_after_timeouts > 0 &&
            scheduler_.consecutive_timeouts() >= tuning_.reconnect_after_timeouts) {
            link_->drop(fmt::format("{} requests in a row got no reply; re-establishing the connection",
                                    scheduler_.consecutive_timeouts()));
            return;  // on_link_state() failed the rest
        }
        arm_tick();
    }

    void post_completions() {
        for (Completion& c : scheduler_.take_completions()) {
            switch (c.outcome.status) {
                case UpstreamStatus::timeout: ++stats_.timeouts; break;
                case UpstreamStatus::expired: ++stats_.expired; break;
                case UpstreamStatus::queue_full: ++stats_.queue_full; break;
                case UpstreamStatus::path_down: ++stats_.path_down; break;
                case UpstreamStatus::ok:
                case UpstreamStatus::cancelled: break;
            }
            asio::post(io_, [done = std::move(c.done), outcome = std::move(c.outcome)] { done(outcome); });
        }
    }

    void arm_tick() {
        const auto at = scheduler_.next_deadline();
        if (!at) {
            tick_timer_.cancel();
            armed_at_.reset();
            return;
        }
        if (armed_at_ && *armed_at_ == *at) return;
        armed_at_ = *at;
        tick_timer_.expires_at(*at);
        std::weak_ptr<Impl> weak = weak_from_this();
        tick_timer_.async_wait([weak](const asio::error_code& ec) {
            auto self = weak.lock();
            if (ec || !self || self->stopped_) return;
            self->armed_at_.reset();
            self->scheduler_.tick(Clock::now());
            self->pump();
        });
    }

    void on_link_state(LinkState state) {
        const auto now = Clock::now();
        if (state == LinkState::up) {
            schedule_poll(now);
            pump();
            return;
        }
        if (state == LinkState::backoff) {
            // Sent requests may have acted: 0x0B; queued ones never left: 0x0A.
            scheduler_.fail_all(UpstreamStatus::path_down, UpstreamStatus::timeout);
            post_completions();
            arm_tick();
            for (auto& unit : units_) {
                abandon_cycle(*unit);
                set_online(*unit, false, now);
            }
        }
    }

    void on_frame(protocol::MbapFrame frame) {
        if (scheduler_.reply(frame.transaction_id, frame.unit_id, std::move(frame.pdu), Clock::now())) {
            ++stats_.replies;
        } else {
            ++stats_.late_replies;
        }
        pump();
    }

    // ---- state polling ---------------------------------------------------------

    void schedule_poll(engine::TimePoint now) {
        next_poll_ = now;
        arm_poll();
    }

    void arm_poll() {
        poll_timer_.expires_at(next_poll_);
        std::weak_ptr<Impl> weak = weak_from_this();
        poll_timer_.async_wait([weak](const asio::error_code& ec) {
            auto self = weak.lock();
            if (ec || !self || self->stopped_) return;
            self->on_poll_timer();
        });
    }

    void on_poll_timer() {
        const auto now = Clock::now();
        if (link_->state() != LinkState::up) return;  // resumes when the link is up again
        next_poll_ += config_.poll_period;
        if (next_poll_ <= now) next_poll_ = now + config_.poll_period;  // fell behind: no burst
        for (auto& unit : units_) {
            if (unit->cycle_running) continue;
            unit->cycle_running = true;
            ++unit->cycle;
            unit->cycle_failed = false;
            unit->step = 0;
            poll_step(*unit);
        }
        pump();
        arm_poll();
    }

    /// Submits the next read of @p unit's cycle, or ends the cycle.
    void poll_step(Unit& unit) {
        while (unit.step < r6_poll_steps) {
            const auto read = r6_poll_read(unit.step, unit.image);
            if (!read) {
                ++unit.step;
                continue;
            }
            UpstreamRequest request;
            request.poll = true;
            request.unit = unit.config.upstream_unit;
            request.pdu = protocol::encode_request(*read);
            request.request_class.priority = engine::Priority::poll;
            std::weak_ptr<Impl> weak = weak_from_this();
            const core::UnitId unit_id = unit.config.unit_id;
            const std::uint64_t cycle = unit.cycle;
            request.done = [weak, unit_id, cycle, read = *read](const UpstreamOutcome& outcome) {
                if (auto self = weak.lock()) self->on_poll_reply(unit_id, cycle, read, outcome);
            };
            scheduler_.submit(std::move(request), Clock::now());
            return;
        }
        finish_cycle(unit);
    }

    void abandon_cycle(Unit& unit) {
        unit.cycle_running = false;
        ++unit.cycle;
    }

    void on_poll_reply(core::UnitId unit_id, std::uint64_t cycle, const protocol::ReadRegistersRequest& read,
                       const UpstreamOutcome& outcome) {
        Unit* unit = find(unit_id);
        if (unit == nullptr || !unit->cycle_running || unit->cycle != cycle || stopped_) return;
        const auto now = Clock::now();
        bool stored = false;
        if (outcome.status == UpstreamStatus::ok) {
            const auto decoded = protocol::decode_response(outcome.response_pdu, protocol::Request{read});
            if (decoded.complete()) {
                if (const auto* regs = std::get_if<protocol::ReadRegistersResponse>(&decoded.value)) {
                    unit->image.update(engine::Table::holding, read.address, regs->values, now);
                    stored = true;
                }
            }
            if (!stored) {
                log_(engine::LogLevel::debug,
                     fmt::format("upstream {}: state read 0x{:04X} x{} of unit {} not stored (exception or "
                                 "malformed reply)", config_.name, read.address, read.count, unit->config.name));
            }
        }
        if (!stored) {
            unit->image.mark_stale(engine::Table::holding, read.address, read.count);
            unit->cycle_failed = true;
        }
        if (outcome.status != UpstreamStatus::ok) {
            // No answer or no connection: the rest of the cycle would fare no better.
            unit->cycle_running = false;
            set_online(*unit, false, now);
            return;
        }
        ++unit->step;
        poll_step(*unit);
        pump();
    }

    void finish_cycle(Unit& unit) {
        unit.cycle_running = false;
        ++stats_.poll_cycles;
        const auto now = Clock::now();
        unit.image.set_offline(false);
        publish(unit, true, now);
    }

    void set_online(Unit& unit, bool online, engine::TimePoint now) {
        if (!online) unit.image.set_offline(true);
        publish(unit, online, now);
    }

    /// Decodes the unit's image; tells the callback when anything it reports changed.
    void publish(Unit& unit, bool online, engine::TimePoint now) {
        engine::DecodedState decoded = decode_r6_state(unit.image);
        std::vector<engine::Alarm> alarms = r6_alarms(unit.image);
        const bool changed = online != unit.state.online || decoded.fields != unit.state.state.fields ||
                             alarms != unit.state.alarms;
        unit.state.online = online;
        unit.state.state = std::move(decoded);
        unit.state.alarms = std::move(alarms);
        unit.state.updated = now;
        if (changed && state_callback_) state_callback_(unit.state);
    }

    asio::io_context& io_;
    config::UpstreamConfig config_;
    UpstreamTuning tuning_;
    engine::LogSink log_;
    UpstreamScheduler scheduler_;
    std::unique_ptr<UpstreamLink> link_;
    asio::steady_timer tick_timer_;
    std::optional<engine::TimePoint> armed_at_;
    asio::steady_timer poll_timer_;
    engine::TimePoint next_poll_{};
    std::vector<std::unique_ptr<Unit>> units_;
    R6StateCallback state_callback_;
    UpstreamStats stats_;
    bool started_ = false;
    bool stopped_ = false;
};

UpstreamTarget::UpstreamTarget(asio::io_context& io, config::UpstreamConfig config, engine::LogSink log,
                               UpstreamTuning tuning)
    : impl_(std::make_shared<Impl>(io, std::move(config), std::move(log), tuning)) {
    impl_->create_link();
}

UpstreamTarget::~UpstreamTarget() {
    // The owner of the callback may be half destroyed already: no report from here on.
    impl_->set_state_callback(nullptr);
    impl_->stop();
}

void UpstreamTarget::start() { impl_->start(); }
void UpstreamTarget::stop() { impl_->stop(); }

void UpstreamTarget::handle(core::UnitId unit, const RequestPdu& request, const ClientRef& client,
                            PduHandler done) {
    impl_->handle(unit, request, client, std::move(done));
}

void UpstreamTarget::client_closed(std::uint64_t connection) { impl_->client_closed(connection); }

void UpstreamTarget::set_state_callback(R6StateCallback callback) {
    impl_->set_state_callback(std::move(callback));
}

std::optional<R6State> UpstreamTarget::state(core::UnitId unit) const {
    const R6State* s = impl_->state(unit);
    if (s == nullptr) return std::nullopt;
    return *s;
}

const engine::RegisterImage* UpstreamTarget::image(core::UnitId unit) const { return impl_->image(unit); }
LinkState UpstreamTarget::link_state() const noexcept { return impl_->link_state(); }
UpstreamStats UpstreamTarget::stats() const noexcept { return impl_->stats(); }
const config::UpstreamConfig& UpstreamTarget::config() const noexcept { return impl_->config(); }

}  // namespace fieldbridge::northbound::upstream
