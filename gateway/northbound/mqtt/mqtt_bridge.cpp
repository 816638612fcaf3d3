#include "northbound/mqtt/mqtt_bridge.hpp"

#include <algorithm>
#include <utility>

#include <asio/post.hpp>

#include "core/log_text.hpp"
#include "northbound/mqtt/command_parser.hpp"
#include "northbound/mqtt/command_runner.hpp"
#include "northbound/mqtt/payloads.hpp"

namespace fieldbridge::northbound::mqtt {

using engine::LogLevel;
using nlohmann::json;

class Bridge::Impl : public std::enable_shared_from_this<Impl> {
public:
    Impl(asio::io_context& io, BridgeSettings settings, std::unique_ptr<Client> client, engine::LogSink log,
         std::unique_ptr<BrokerProbe> probe)
        : io_(io),
          s_(std::move(settings)),
          client_(std::move(client)),
          log_(std::move(log)),
          outbox_(s_.outbox_capacity, s_.outbox_max_bytes),
          wake_timer_(io),
          diag_timer_(io),
          stop_timer_(io),
          reconnect_(io, ReconnectSettings{s_.reconnect_initial, s_.reconnect_max, s_.probe_period, s_.probe_timeout},
                     std::move(probe), [this] {
                         if (!stopping_) client_->connect();
                     },
                     log_) {}

    struct Device {
        std::shared_ptr<DeviceSource> source;
        StateThrottle throttle;
        AlarmTracker alarms;
        std::string state_topic;
        std::string alarm_topic;
        bool scheduled = false;
    };

    /// The bridge's throttle settings, with the deadbands of the source's points (a
    /// point's own `deadband` wins over `mqtt.deadband` of the same field name).
    [[nodiscard]] ThrottleSettings throttle_for(const DeviceSource& source) const {
        ThrottleSettings settings = s_.throttle;
        if (const core::PointModel* points = source.points()) {
            for (const core::PointDef& point : points->points) {
                if (point.deadband) settings.deadband[point.name] = *point.deadband;
            }
        }
        return settings;
    }

    void set_sources(std::vector<std::shared_ptr<DeviceSource>> sources) {
        for (auto& [name, device] : devices_) device->source->set_listener({});
        devices_.clear();
        for (auto& source : sources) {
            auto device = std::make_unique<Device>(Device{source, StateThrottle(throttle_for(*source)), AlarmTracker(s_.alarms),
                                                          topic(source->name(), "state"),
                                                          topic(source->name(), "alarm"), false});
            const std::weak_ptr<Impl> weak = weak_from_this();
            const std::string name = source->name();
            const DeviceSource* identity = source.get();
            source->set_listener(SourceListener{
                [weak, name, identity] {
                    if (auto self = weak.lock()) self->schedule(name, identity);
                },
                [weak, name, identity](const engine::DeviceNotice& notice) {
                    if (auto self = weak.lock()) self->notice(name, identity, notice);
                }});
            devices_[name] = std::move(device);
        }
        if (started_ && !stopping_) evaluate_all();
    }

    void start() {
        if (started_) return;
        started_ = true;
        const std::weak_ptr<Impl> weak = weak_from_this();
        ClientEvents events;
        events.connected = [weak] { if (auto self = weak.lock()) self->on_connected(); };
        events.connect_failed = [weak](const std::string& reason) {
            if (auto self = weak.lock()) self->on_connect_failed(reason);
        };
        events.connection_lost = [weak](const std::string& cause) {
            if (auto self = weak.lock()) self->on_connection_lost(cause);
        };
        events.message = [weak](Message m) { if (auto self = weak.lock()) self->on_message(std::move(m)); };
        events.published = [weak](std::uint64_t id, bool ok) {
            if (auto self = weak.lock()) self->on_published(id, ok);
        };
        events.inbound_dropped = [weak](std::uint64_t count) {
            if (auto self = weak.lock()) self->on_inbound_dropped(count);
        };
        client_->set_events(std::move(events));
        log(LogLevel::info, "MQTT: connecting to the broker; topics under " + s_.prefix + "/");
        client_->connect();
        evaluate_all();
        arm_diag();
    }

    void stop(std::function<void()> done) {
        if (stopping_) {
            asio::post(io_, std::move(done));
            return;
        }
        stopping_ = true;
        stop_done_ = std::move(done);
        wake_timer_.cancel();
        diag_timer_.cancel();
        reconnect_.cancel();
        outbox_.clear();
        if (!client_->connected()) {
            finish_stop();
            return;
        }
        offline_id_ = client_->publish(Message{status_topic(), "offline", s_.qos, true});
        if (offline_id_ == 0) {
            disconnect();
            return;
        }
        // Wait for the broker to take `offline`, not forever.
        stop_timer_.expires_after(s_.stop_timeout);
        stop_timer_.async_wait([weak = weak_from_this()](const std::error_code& error) {
            if (auto self = weak.lock(); self && !error) self->disconnect();
        });
    }

    /// The owner is going away: nothing runs after this.
    void shutdown() {
        for (auto& [name, device] : devices_) device->source->set_listener({});
        devices_.clear();
        client_->set_events({});
        wake_timer_.cancel();
        diag_timer_.cancel();
        reconnect_.cancel();
        stop_timer_.cancel();
    }

    [[nodiscard]] bool connected() const noexcept { return client_->connected(); }
    void leave_client_to_process_exit() noexcept { client_->leave_to_process_exit(); }

    [[nodiscard]] BridgeStats stats() const {
        BridgeStats s = stats_;
        s.dropped = outbox_.dropped();
        s.superseded = outbox_.superseded();
        s.in_flight = in_flight_.size();
        s.queued = outbox_.size();
        return s;
    }

    const BridgeSettings& settings() const noexcept { return s_; }
    DiagProvider diag_;

private:
    [[nodiscard]] std::string topic(const std::string& device, const char* leaf) const {
        return s_.prefix + "/" + device + "/" + leaf;
    }
    [[nodiscard]] std::string status_topic() const { return s_.prefix + "/status"; }

    void log(LogLevel level, const std::string& message) const { log_(level, message); }

    // ---- connection -----------------------------------------------------------

    void on_connected() {
        if (stopping_) return;
        ++stats_.connects;
        reconnect_.reset();
        log(LogLevel::info, "MQTT: connected; publishing availability, state and alarms");
        client_->subscribe(s_.prefix + "/+/cmd", s_.qos);
        // Alarm events and command results the last connection took but never
        // confirmed go first, in the order they were made, then what waited meanwhile.
        if (!unconfirmed_.empty()) {
            log(LogLevel::info, "MQTT: sending again " + std::to_string(unconfirmed_.size()) +
                                    " event(s) and result(s) the broker had not confirmed");
        }
        for (auto it = unconfirmed_.rbegin(); it != unconfirmed_.rend(); ++it) outbox_.put_first(std::move(it->second));
        stats_.resent += unconfirmed_.size();
        unconfirmed_.clear();
        outbox_.put_first(Message{status_topic(), "online", s_.qos, true});
        // The broker may have lost every retained value (restarted without
        // persistence): publish everything again.
        const ClockPair clock = ClockPair::now();
        for (auto& [name, device] : devices_) {
            device->throttle.reset();
            outbox_.put(alarm_set(name, *device, clock));
        }
        evaluate_all();
        pump();
    }

    /// mqtt.uri as a list: after a failed attempt or a lost connection, the next
    /// broker of the list (wrapping to the first) gets the next attempt.
    void walk_to_next_server() {
        const std::size_t count = client_->server_count();
        if (count < 2) return;
        server_ = (server_ + 1) % count;
        client_->select_server(server_);
    }

    void on_connect_failed(const std::string& reason) {
        ++stats_.connect_failures;
        if (stopping_) return;
        walk_to_next_server();
        const auto delay = reconnect_.schedule();
        log(LogLevel::warning, "MQTT: cannot connect to the broker (" + reason + "); retrying in " +
                                   std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(delay).count()) +
                                   " ms, or as soon as its port accepts connections again; Modbus TCP and the "
                                   "lines are not affected");
    }

    void on_connection_lost(const std::string& cause) {
        ++stats_.connection_losses;
        // What the broker did not confirm may not have reached it: kept for the next
        // connection (retained values are republished whole then anyway).
        for (auto& [id, message] : in_flight_) {
            if (!message.retained) unconfirmed_.emplace(id, std::move(message));
        }
        in_flight_.clear();
        if (stopping_) return;
        log(LogLevel::warning, "MQTT: connection to the broker lost (" + cause + "); reconnecting");
        walk_to_next_server();
        reconnect_.schedule();
    }

    void disconnect() {
        stop_timer_.cancel();
        client_->disconnect(s_.stop_timeout, [weak = weak_from_this()] {
            if (auto self = weak.lock()) self->finish_stop();
        });
    }

    void finish_stop() {
        auto done = std::move(stop_done_);
        stop_done_ = nullptr;
        if (done) asio::post(io_, std::move(done));
    }

    // ---- publishing -----------------------------------------------------------

    void send(Message message) {
        outbox_.put(std::move(message));
        pump();
    }

    void pump() {
        while (!stopping_ && client_->connected() && in_flight_.size() < s_.max_in_flight && !outbox_.empty()) {
            Message m = *outbox_.take();
            const std::uint64_t id = client_->publish(m);
            if (id == 0) {
                ++stats_.publish_failures;
                break;
            }
            in_flight_.emplace(id, std::move(m));
        }
    }

    void on_published(std::uint64_t id, bool ok) {
        if (id == offline_id_ && offline_id_ != 0) {
            offline_id_ = 0;
            disconnect();
            return;
        }
        const auto it = in_flight_.find(id);
        if (it == in_flight_.end()) return;  // from an earlier connection
        if (ok) {
            ++stats_.published;
        } else {
            ++stats_.publish_failures;
            // Paho fails what is in flight when the connection breaks, maybe before it
            // reports the loss: keep events and results for the next connection, and
            // drop them only if the connection turns out to be fine (a refusal).
            if (!it->second.retained) {
                unconfirmed_.emplace(id, std::move(it->second));
                settle_unconfirmed();
            }
        }
        in_flight_.erase(it);
        pump();
    }

    void settle_unconfirmed() {
        if (settle_pending_) return;
        settle_pending_ = true;
        asio::post(io_, [weak = weak_from_this()] {
            auto self = weak.lock();
            if (!self) return;
            self->settle_pending_ = false;
            if (!self->client_->connected() || self->unconfirmed_.empty()) return;
            self->log(LogLevel::warning, "MQTT: the broker refused " + std::to_string(self->unconfirmed_.size()) +
                                             " publication(s) on a working connection; dropped (check its ACL for " +
                                             self->s_.prefix + "/#)");
            self->stats_.refused += self->unconfirmed_.size();
            self->unconfirmed_.clear();
        });
    }

    // ---- devices --------------------------------------------------------------

    [[nodiscard]] Message alarm_set(const std::string& name, const Device& device, const ClockPair& clock) const {
        return Message{device.alarm_topic, alarm_set_payload(name, device.alarms.active(), clock).dump(), s_.qos, true};
    }

    Device* find(const std::string& name, const DeviceSource* identity) {
        const auto it = devices_.find(name);
        if (it == devices_.end() || it->second->source.get() != identity) return nullptr;
        return it->second.get();
    }

    void schedule(const std::string& name, const DeviceSource* identity) {
        Device* device = find(name, identity);
        if (device == nullptr || device->scheduled || stopping_) return;
        device->scheduled = true;
        asio::post(io_, [weak = weak_from_this(), name, identity] {
            auto self = weak.lock();
            if (!self) return;
            Device* d = self->find(name, identity);
            if (d == nullptr) return;
            d->scheduled = false;
            if (self->stopping_) return;
            self->evaluate(name, *d, engine::Clock::now());
            self->arm_wake();
            self->pump();
        });
    }

    void notice(const std::string& name, const DeviceSource* identity, const engine::DeviceNotice& notice) {
        Device* device = find(name, identity);
        if (device == nullptr) return;
        device->alarms.notice(notice, engine::Clock::now());
        schedule(name, identity);
    }

    void evaluate(const std::string& name, Device& device, engine::TimePoint now) {
        const SourceState state = device.source->state();
        const std::vector<AlarmEvent> events = device.alarms.update(device.source->alarms(), state.online, now);
        const ClockPair clock = ClockPair::now();
        for (const AlarmEvent& event : events) {
            ++stats_.alarm_events;
            log(LogLevel::info, "MQTT: " + name + " alarm " + event.alarm.code +
                                    (event.transition == AlarmTransition::raised ? " raised: " : " cleared: ") +
                                    event.alarm.text);
            outbox_.put(Message{device.alarm_topic, alarm_event_payload(name, event, clock).dump(), s_.qos, false});
        }
        if (!events.empty()) outbox_.put(alarm_set(name, device, clock));
        if (client_->connected() && device.throttle.due(state, now)) {
            ++stats_.state_messages;
            outbox_.put(Message{device.state_topic,
                                state_payload(name, device.source->type(), state, clock).dump(), s_.qos, true});
            device.throttle.published(state, now);
        }
        // Remember when to look again.
        const auto consider = [&](std::optional<engine::TimePoint> t) {
            if (t && (!device_wake_ || *t < *device_wake_)) device_wake_ = t;
        };
        if (client_->connected()) consider(device.throttle.next_check(state));
        consider(device.alarms.next_deadline());
    }

    void evaluate_all() {
        if (stopping_) return;
        const engine::TimePoint now = engine::Clock::now();
        for (auto& [name, device] : devices_) evaluate(name, *device, now);
        arm_wake();
        pump();
    }

    /// One timer for every device: the nearest hold / heartbeat, or the watch period.
    void arm_wake() {
        if (!started_ || stopping_) return;
        engine::TimePoint at = engine::Clock::now() + s_.watch_period;
        if (device_wake_ && *device_wake_ < at) at = *device_wake_;
        device_wake_.reset();
        if (wake_armed_ && wake_at_ <= at) return;
        wake_armed_ = true;
        wake_at_ = at;
        wake_timer_.expires_at(at);
        wake_timer_.async_wait([weak = weak_from_this()](const std::error_code& error) {
            auto self = weak.lock();
            if (!self || error) return;
            self->wake_armed_ = false;
            self->evaluate_all();
        });
    }

    // ---- diagnostics ----------------------------------------------------------

    void arm_diag() {
        diag_timer_.expires_after(s_.diag_period);
        diag_timer_.async_wait([weak = weak_from_this()](const std::error_code& error) {
            auto self = weak.lock();
            if (!self || error || self->stopping_) return;
            self->publish_diag();
            self->arm_diag();
        });
    }

    void publish_diag() {
        if (!client_->connected()) return;  // counters are a snapshot: the next one will do
        json payload = diag_ ? diag_() : json::object();
        if (!payload.is_object()) payload = json::object();
        const BridgeStats s = stats();
        payload["mqtt"] = {{"connects", s.connects},
                           {"connect_failures", s.connect_failures},
                           {"connection_losses", s.connection_losses},
                           {"published", s.published},
                           {"publish_failures", s.publish_failures},
                           {"dropped", s.dropped},
                           {"resent", s.resent},
                           {"refused", s.refused},
                           {"superseded", s.superseded},
                           {"state_messages", s.state_messages},
                           {"alarm_events", s.alarm_events},
                           {"commands", s.commands},
                           {"commands_failed", s.commands_failed},
                           {"commands_too_large", s.commands_too_large},
                           {"commands_dropped", s.commands_dropped},
                           {"in_flight", s.in_flight},
                           {"queued", s.queued}};
        const WallTime now = WallClock::now();
        payload["time"] = iso8601_utc(now);
        payload["time_ms"] = epoch_ms(now);
        send(Message{s_.prefix + "/diag", payload.dump(), s_.qos, false});
    }

    // ---- commands -------------------------------------------------------------

    void on_message(Message message) {
        // <prefix>/<device>/cmd, one level for the device.
        const std::string head = s_.prefix + "/";
        const std::string tail = "/cmd";
        const std::string& t = message.topic;
        if (t.size() <= head.size() + tail.size() || t.compare(0, head.size(), head) != 0 ||
            t.compare(t.size() - tail.size(), tail.size(), tail) != 0) {
            return;
        }
        const std::string name = t.substr(head.size(), t.size() - head.size() - tail.size());
        if (name.find('/') != std::string::npos) return;
        handle_command(name, message);
    }

    void on_inbound_dropped(std::uint64_t count) {
        stats_.commands_dropped += count;
        unlogged_drops_ += count;
        const auto now = std::chrono::steady_clock::now();
        if (last_drop_log_ != std::chrono::steady_clock::time_point{} && now - last_drop_log_ < drop_log_interval) {
            return;
        }
        log(LogLevel::warning, "MQTT: " + std::to_string(unlogged_drops_) +
                                   " received message(s) dropped unanswered: more were waiting than "
                                   "mqtt.max_queued_commands / max_queued_command_bytes allow (a client floods the "
                                   "cmd topics?); logged at most every " +
                                   std::to_string(drop_log_interval.count()) + " s");
        unlogged_drops_ = 0;
        last_drop_log_ = now;
    }

    /// @p text cut to max_command_id_length bytes (on a UTF-8 character boundary).
    [[nodiscard]] std::string bounded(std::string text) const {
        if (text.size() <= s_.max_command_id_length) return text;
        std::size_t end = s_.max_command_id_length;
        while (end > 0 && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) --end;
        text.resize(end);
        return text;
    }

    /// The id as echoed and logged: a string id beyond the bound is cut.
    [[nodiscard]] json bounded(const json& id) const {
        return id.is_string() ? json(bounded(id.get<std::string>())) : id;
    }

    void handle_command(const std::string& name, const Message& message) {
        ++stats_.commands;
        if (message.payload.size() > s_.max_command_bytes) {
            ++stats_.commands_too_large;
            answer(name, json(), {},
                   CommandOutcome{false, "too_large",
                                  "the command is larger than " + std::to_string(s_.max_command_bytes) +
                                      " bytes (mqtt.max_command_bytes); not read",
                                  std::nullopt, {}});
            return;
        }
        const ParseResult parsed = [&]() -> ParseResult {
            const auto it = devices_.find(name);
            // No device: parsed only for the id and op the refusal echoes.
            if (it == devices_.end()) return parse_command(message.payload, engine::OperationSet{}, {});
            // Some ops depend on the device's registers (WTEC grip / release: the init direction).
            const DeviceSource& source = *it->second->source;
            return parse_command(message.payload, source.operations(), source.state().raw, source.points());
        }();
        json id;
        std::string op;
        if (const auto* error = std::get_if<CommandError>(&parsed)) {
            id = bounded(error->id);
            op = bounded(error->op);
        } else {
            id = bounded(std::get<ParsedCommand>(parsed).id);
            op = bounded(std::get<ParsedCommand>(parsed).op);
        }
        const auto refuse = [&](std::string kind, std::string text) {
            answer(name, id, op, CommandOutcome{false, std::move(kind), std::move(text), std::nullopt, {}});
        };
        const auto it = devices_.find(name);
        if (it == devices_.end()) {
            refuse("unknown_device", "no device " + core::quoted(name) + " on this gateway");
            return;
        }
        if (message.retained) {
            // A retained command would run again on every reconnect: never executed.
            refuse("retained", "retained commands are not executed; publish the command without the retain flag "
                               "and clear the retained message");
            return;
        }
        if (stopping_) {
            refuse("unavailable", "the gateway is stopping");
            return;
        }
        if (!it->second->source->commands_enabled()) {
            refuse("commands_disabled", "commands are disabled for '" + name + "' (mqtt_commands: false)");
            return;
        }
        if (const auto* error = std::get_if<CommandError>(&parsed)) {
            // The message may quote the op: bounded like it.
            refuse(std::string(to_string(error->kind)), bounded(error->message));
            return;
        }
        const auto& command = std::get<ParsedCommand>(parsed);
        run_command(io_, it->second->source, command.requests,
                    [weak = weak_from_this(), source = it->second->source, read = command.read_points, name, id,
                     op](CommandOutcome outcome) {
                        // `read`: the values as the image holds them now, the replies applied.
                        if (outcome.ok && !read.empty()) outcome.values = point_values(source->state(), read);
                        if (auto self = weak.lock()) self->answer(name, id, op, outcome);
                    });
    }

    void answer(const std::string& name, const json& id, const std::string& op, const CommandOutcome& outcome) {
        if (!outcome.ok) ++stats_.commands_failed;
        log(outcome.ok ? LogLevel::info : LogLevel::warning,
            "MQTT: command " + id.dump() + " " + core::quoted(op) + " to " + core::quoted(name) +
                (outcome.ok ? std::string(": ok") : ": " + outcome.error + ": " + outcome.message));
        send(Message{topic(name, "cmd/result"), command_result_payload(name, id, op, outcome, ClockPair::now()).dump(),
                     s_.qos, false});
    }

    asio::io_context& io_;
    BridgeSettings s_;
    std::unique_ptr<Client> client_;
    engine::LogSink log_;
    Outbox outbox_;
    std::map<std::string, std::unique_ptr<Device>, std::less<>> devices_;
    asio::steady_timer wake_timer_;
    asio::steady_timer diag_timer_;
    asio::steady_timer stop_timer_;
    ReconnectSchedule reconnect_;
    bool started_ = false;
    bool stopping_ = false;
    std::size_t server_ = 0;  ///< the client's server of the next attempt (mqtt.uri as a list)
    bool wake_armed_ = false;
    engine::TimePoint wake_at_{};
    std::optional<engine::TimePoint> device_wake_;
    /// Handed to the client, not yet confirmed, by publication id (= sending order).
    std::map<std::uint64_t, Message> in_flight_;
    /// Transient messages whose publication failed or whose connection was lost,
    /// sent again first on the next connection.
    std::map<std::uint64_t, Message> unconfirmed_;
    bool settle_pending_ = false;
    std::uint64_t offline_id_ = 0;
    std::function<void()> stop_done_;
    BridgeStats stats_;
    static constexpr std::chrono::seconds drop_log_interval{10};
    std::uint64_t unlogged_drops_ = 0;
    std::chrono::steady_clock::time_point last_drop_log_{};
};

Bridge::Bridge(asio::io_context& io, BridgeSettings settings, std::unique_ptr<Client> client, engine::LogSink log,
               std::unique_ptr<BrokerProbe> probe)
    : impl_(std::make_shared<Impl>(io, std::move(settings), std::move(client), std::move(log), std::move(probe))) {}

Bridge::~Bridge() { impl_->shutdown(); }

void Bridge::set_sources(std::vector<std::shared_ptr<DeviceSource>> sources) { impl_->set_sources(std::move(sources)); }
void Bridge::set_diag_provider(DiagProvider provider) { impl_->diag_ = std::move(provider); }
void Bridge::start() { impl_->start(); }
void Bridge::stop(std::function<void()> done) { impl_->stop(std::move(done)); }
void Bridge::leave_client_to_process_exit() noexcept { impl_->leave_client_to_process_exit(); }
bool Bridge::connected() const noexcept { return impl_->connected(); }
BridgeStats Bridge::stats() const { return impl_->stats(); }
const BridgeSettings& Bridge::settings() const noexcept { return impl_->settings(); }

}  // namespace fieldbridge::northbound::mqtt
