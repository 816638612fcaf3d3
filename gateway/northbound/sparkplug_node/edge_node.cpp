#include "northbound/sparkplug_node/edge_node.hpp"

#include <algorithm>
#include <span>
#include <type_traits>
#include <utility>
#include <variant>

#include <asio/post.hpp>

#include "core/error.hpp"
#include "core/log_text.hpp"
#include "northbound/mqtt/command_parser.hpp"
#include "northbound/mqtt/command_runner.hpp"
#include "northbound/sparkplug/command_decoder.hpp"
#include "northbound/sparkplug/payload_codec.hpp"
#include "northbound/sparkplug_session/messages.hpp"
#include "northbound/sparkplug_session/topics.hpp"

namespace fieldbridge::northbound::sparkplug_node {
namespace {

using core::LogLevel;
using sparkplug::Metric;
namespace session = sparkplug_session;

/// Device metrics' aliases start here; the node's own metrics take those below.
constexpr std::uint64_t first_device_alias = 1u << 20;
/// How long a DISCONNECT may wait for what is in flight (the NDEATH).
constexpr std::chrono::milliseconds disconnect_timeout{2000};

std::uint64_t utc_ms() {
    return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::milliseconds>(
                                          std::chrono::system_clock::now().time_since_epoch())
                                          .count());
}

/// Copies @p state's field @p name into @p into (replacing or adding it).
void take_field(engine::DecodedState& into, const engine::DecodedState& state, std::string_view name) {
    const engine::Field* field = state.find(name);
    if (field == nullptr) return;
    auto it = std::find_if(into.fields.begin(), into.fields.end(), [&](const engine::Field& f) { return f.name == name; });
    if (it == into.fields.end()) {
        into.fields.push_back(*field);
    } else {
        *it = *field;
    }
}

/// The device's whole field list (@p shape) with the fields of @p state it lacks.
engine::DecodedState with_fields(engine::DecodedState shape, const engine::DecodedState& state) {
    for (const engine::Field& field : state.fields) {
        if (shape.find(field.name) == nullptr) shape.fields.push_back(field);
    }
    return shape;
}

}  // namespace

EdgeNode::EdgeNode(asio::io_context& io, EdgeNodeSettings settings, std::unique_ptr<mqtt::Client> client,
                   engine::LogSink log_sink, NodeProbe probe)
    : io_(io),
      settings_(std::move(settings)),
      client_(std::move(client)),
      log_(std::move(log_sink)),
      probe_(std::move(probe)),
      store_(settings_.state_dir),
      catalogue_(first_device_alias),
      session_(settings_.session, {}, {}),
      reconnect_(io, settings_.reconnect, nullptr, [this] { connect_attempt(); }, log_),
      sweep_timer_(io),
      tick_timer_(io),
      retry_timer_(io) {
    if (!store_.warning().empty()) log(LogLevel::warning, "Sparkplug: " + store_.warning());
    mqtt::ClientEvents events;
    events.connected = [this] {
        reconnect_.reset();
        ++counters_.connections;
        log(LogLevel::info, "Sparkplug: connected (bdSeq " + std::to_string(session_.bd_seq().value_or(0)) +
                                ", group " + core::quoted(settings_.session.node.group_id) + ", edge node " +
                                core::quoted(settings_.session.node.edge_node_id) + ")");
        apply(session_.connected(now()));
    };
    events.connect_failed = [this](const std::string& reason) {
        log(LogLevel::warning, "Sparkplug: cannot connect to the broker: " + core::quoted(reason) +
                                   "; trying again (the next server of sparkplug.servers, if any)");
        waiting_.clear();
        in_flight_ = 0;
        apply(session_.connection_lost());
        next_server();
        reconnect_.schedule();
    };
    events.connection_lost = [this](const std::string& cause) {
        if (stopping_) return;
        log(LogLevel::warning, "Sparkplug: lost the broker: " + core::quoted(cause) +
                                   "; data is kept in the offline buffer until the next session");
        counters_.publish_dropped += waiting_.size();
        waiting_.clear();
        in_flight_ = 0;
        apply(session_.connection_lost());
        next_server();
        reconnect_.schedule();
    };
    events.message = [this](mqtt::Message message) { on_message(message); };
    events.published = [this](std::uint64_t, bool ok) {
        if (in_flight_ > 0) --in_flight_;
        if (!ok) ++counters_.publish_dropped;
        drain();
    };
    events.inbound_dropped = [this](std::uint64_t count) {
        counters_.commands_refused += count;
        log(LogLevel::warning, "Sparkplug: " + std::to_string(count) +
                                   " received messages dropped: commands arrive faster than they can be handled");
    };
    client_->set_events(std::move(events));
}

EdgeNode::~EdgeNode() {
    // The listeners stay on the sources (a source may serve the next node already:
    // the R6 units' are shared); they do nothing once this flag is down.
    *alive_ = false;
}

session::Instant EdgeNode::now() const { return session::Instant{session::SteadyClock::now(), utc_ms()}; }

void EdgeNode::log(LogLevel level, const std::string& text) const {
    if (log_.enabled(level)) log_(level, text);
}

bool EdgeNode::online() const noexcept { return session_.phase() == session::Phase::online; }

sparkplug::DeviceShape EdgeNode::shape_of(const mqtt::DeviceSource& source, const engine::DecodedState& state) const {
    sparkplug::DeviceShape shape;
    shape.name = source.name();
    shape.points = source.points();
    shape.state = state;
    shape.deadband = settings_.deadband;
    if (source.commands_enabled()) {
        shape.operations = source.operations();
        const std::span<const engine::FieldSetter> setters = engine::field_setters(shape.operations);
        for (const engine::FieldSetter& setter : setters) shape.writable_fields.insert(std::string(setter.field));
    }
    return shape;
}

std::vector<Metric> EdgeNode::birth_metrics(const Device& device, const engine::DecodedState& state,
                                            std::uint64_t now_ms) const {
    const std::string& name = device.source->name();
    std::vector<Metric> metrics = catalogue_.birth_metrics(name, state, now_ms, settings_.session.aliases);
    const auto& known = catalogue_.metrics(name);
    for (std::size_t i = 0; i < metrics.size() && i < known.size(); ++i) {
        if (!known[i].is_command()) continue;
        if (known[i].argument.empty()) {
            metrics[i].value = false;  // a trigger reads false: writing true runs the op
        } else if (const auto it = device.arguments.find(known[i].name); it != device.arguments.end()) {
            metrics[i].value = it->second;
        }
    }
    return metrics;
}

std::vector<Metric> EdgeNode::current_node_metrics(std::uint64_t now_ms) {
    NodeSnapshot snapshot = probe_ ? probe_() : NodeSnapshot{};
    snapshot.commands_accepted = counters_.commands_accepted;
    snapshot.commands_refused = counters_.commands_refused;
    std::vector<Metric> metrics = node_metrics(snapshot, now_ms);
    for (Metric& metric : metrics) {
        auto [it, added] = node_aliases_.try_emplace(*metric.name, node_aliases_.size() + 1);
        static_cast<void>(added);
        if (settings_.session.aliases) metric.alias = it->second;
    }
    return metrics;
}

void EdgeNode::set_sources(std::vector<std::shared_ptr<mqtt::DeviceSource>> sources) {
    std::vector<Device> next;
    next.reserve(sources.size());
    for (auto& source : sources) {
        Device device;
        device.source = std::move(source);
        const auto old = std::find_if(devices_.begin(), devices_.end(), [&](const Device& d) {
            return d.source->name() == device.source->name();
        });
        if (old != devices_.end()) {
            device.online = old->online;
            device.published = old->published;
            device.arguments = old->arguments;
        }
        next.push_back(std::move(device));
    }
    for (Device& old : devices_) {
        const bool kept = std::any_of(next.begin(), next.end(), [&](const Device& d) { return d.source == old.source; });
        if (!kept) old.source->set_listener({});
        catalogue_.remove_device(old.source->name());
    }
    devices_ = std::move(next);
    const session::Instant at = now();
    std::vector<session::DeviceMetrics> definitions;
    for (std::size_t i = 0; i < devices_.size(); ++i) {
        Device& device = devices_[i];
        const mqtt::SourceState state = device.source->state();
        catalogue_.add_device(shape_of(*device.source, with_fields(device.source->shape(), state.decoded)));
        definitions.push_back(session::DeviceMetrics{device.source->name(), birth_metrics(device, state.decoded, at.utc_ms)});
        listen(i);
    }
    node_published_ = current_node_metrics(at.utc_ms);
    if (!started_) {
        session_ = session::Session(settings_.session, node_published_, std::move(definitions));
        for (Device& device : devices_) device.online = false;
    } else {
        apply(session_.reload(node_published_, std::move(definitions), at));
    }
    for (Device& device : devices_) refresh(device);
}

void EdgeNode::listen(std::size_t index) {
    mqtt::SourceListener listener;
    listener.changed = [this, index, alive = std::weak_ptr<bool>(alive_)] {
        const auto flag = alive.lock();
        if (!flag || !*flag || index >= devices_.size()) return;
        devices_[index].dirty = true;
        if (refresh_posted_) return;
        refresh_posted_ = true;
        asio::post(io_, [this, alive] {
            const auto f = alive.lock();
            if (!f || !*f) return;
            refresh_posted_ = false;
            refresh_dirty();
        });
    };
    devices_[index].source->set_listener(std::move(listener));
}

void EdgeNode::refresh_dirty() {
    for (Device& device : devices_) {
        if (!device.dirty) continue;
        device.dirty = false;
        refresh(device);
    }
    arm_tick();
}

void EdgeNode::refresh(Device& device) {
    if (stopping_) return;
    const std::string& name = device.source->name();
    const mqtt::SourceState state = device.source->state();
    const session::Instant at = now();
    if (!state.online) {
        if (!device.online) return;
        device.online = false;
        apply(session_.device_offline(name, at));
        return;
    }
    if (!device.online || !catalogue_.covers(name, state.decoded)) {
        // Every field the device can have, so that it is born once, not once per
        // register block as its first polls come in.
        catalogue_.add_device(shape_of(*device.source, with_fields(device.source->shape(), state.decoded)));
        device.online = true;
        device.published = state.decoded;
        apply(session_.device_online(name, birth_metrics(device, state.decoded, at.utc_ms), at));
        return;
    }
    std::vector<Metric> changed =
        catalogue_.changed_metrics(name, device.published, state.decoded, at.utc_ms, settings_.session.aliases);
    if (changed.empty()) return;
    for (const Metric& metric : changed) {
        const sparkplug::CatalogueMetric* entry = catalogue_.find(name, sparkplug::MetricReference{metric.name, metric.alias});
        if (entry != nullptr) take_field(device.published, state.decoded, entry->field);
    }
    apply(session_.device_changed(name, std::move(changed), at));
}

void EdgeNode::sweep() {
    for (Device& device : devices_) refresh(device);
    const session::Instant at = now();
    if (at.mono >= next_node_sample_) {
        next_node_sample_ = at.mono + settings_.node_period;
        sample_node();
    }
    arm_tick();
    sweep_timer_.expires_after(settings_.sweep_period);
    sweep_timer_.async_wait([this, alive = std::weak_ptr<bool>(alive_)](const std::error_code& error) {
        const auto flag = alive.lock();
        if (error || !flag || !*flag || stopping_) return;
        sweep();
    });
}

void EdgeNode::sample_node() {
    const session::Instant at = now();
    std::vector<Metric> current = current_node_metrics(at.utc_ms);
    std::vector<Metric> changed = changed_node_metrics(node_published_, current);
    node_published_ = std::move(current);
    if (changed.empty()) return;
    apply(session_.node_changed(std::move(changed), at));
}

void EdgeNode::arm_tick() {
    const auto due = session_.next_deadline();
    if (!due || stopping_) return;
    if (tick_due_ && *tick_due_ <= *due) return;
    tick_due_ = *due;
    tick_timer_.expires_at(*due);
    tick_timer_.async_wait([this, alive = std::weak_ptr<bool>(alive_)](const std::error_code& error) {
        const auto flag = alive.lock();
        if (error || !flag || !*flag) return;  // cancelled by an earlier deadline: that one runs
        tick_due_.reset();
        apply(session_.tick(now()));
        arm_tick();
    });
}

void EdgeNode::apply(const session::Actions& actions) {
    for (const session::Action& action : actions) {
        std::visit(
            [this](const auto& a) {
                using A = std::decay_t<decltype(a)>;
                if constexpr (std::is_same_v<A, session::SetWill>) {
                    client_->set_will(mqtt::Message{a.topic, sparkplug::encode(a.payload), a.qos, a.retain});
                } else if constexpr (std::is_same_v<A, session::Subscribe>) {
                    client_->subscribe(a.topic, a.qos);
                } else if constexpr (std::is_same_v<A, session::Unsubscribe>) {
                    client_->unsubscribe(a.topic);
                } else if constexpr (std::is_same_v<A, session::Publish>) {
                    send(mqtt::Message{a.topic, sparkplug::encode(a.payload), a.qos, a.retain});
                } else if constexpr (std::is_same_v<A, session::Disconnect>) {
                    disconnect(a.next_server);
                } else {
                    log(LogLevel::warning, a.text);
                }
            },
            action);
    }
}

void EdgeNode::send(mqtt::Message message) {
    if (waiting_.size() >= settings_.max_waiting) {
        waiting_.pop_front();
        if (counters_.publish_dropped++ == 0) {
            log(LogLevel::warning, "Sparkplug: publications wait longer than the broker takes them; the oldest are "
                                   "dropped (the host sees a seq gap and may ask for a rebirth)");
        }
    }
    waiting_.push_back(std::move(message));
    drain();
}

void EdgeNode::drain() {
    // In order, at most publish_window handed to the client at once: a burst (the
    // offline buffer's replay) must not meet the client's own in-flight limit.
    while (!waiting_.empty() && in_flight_ < settings_.publish_window) {
        if (client_->publish(waiting_.front()) == 0) {
            if (client_->connected()) {
                // Refused for now: again on the next report, or shortly when none is due.
                if (in_flight_ == 0) {
                    retry_timer_.expires_after(std::chrono::milliseconds(50));
                    retry_timer_.async_wait([this, alive = std::weak_ptr<bool>(alive_)](const std::error_code& error) {
                        const auto flag = alive.lock();
                        if (!error && flag && *flag) drain();
                    });
                }
                return;
            }
            counters_.publish_dropped += waiting_.size();
            waiting_.clear();  // the connection went: the next session births again
            break;
        }
        waiting_.pop_front();
        ++in_flight_;
    }
    if (waiting_.empty() && disconnect_after_) {
        const bool walk = *disconnect_after_;
        disconnect_after_.reset();
        disconnect(walk);
    }
}

void EdgeNode::disconnect(bool walk) {
    if (!waiting_.empty()) {
        // What the session published before (the NDEATH) goes out first.
        disconnect_after_ = walk;
        return;
    }
    client_->disconnect(disconnect_timeout, [this, walk, alive = std::weak_ptr<bool>(alive_)] {
        const auto flag = alive.lock();
        if (!flag || !*flag) return;
        in_flight_ = 0;
        if (stopping_) {
            if (stop_done_) std::exchange(stop_done_, {})();
            return;
        }
        apply(session_.connection_lost());
        if (walk) next_server();
        connect_attempt();
    });
}

void EdgeNode::start() {
    started_ = true;
    next_node_sample_ = engine::Clock::now() + settings_.node_period;
    connect_attempt();
    sweep_timer_.expires_after(settings_.sweep_period);
    sweep_timer_.async_wait([this, alive = std::weak_ptr<bool>(alive_)](const std::error_code& error) {
        const auto flag = alive.lock();
        if (error || !flag || !*flag || stopping_) return;
        sweep();
    });
}

void EdgeNode::next_server() {
    const std::size_t count = std::max<std::size_t>(1, client_->server_count());
    server_ = (server_ + 1) % count;
}

void EdgeNode::connect_attempt() {
    if (stopping_) return;
    std::uint8_t bd_seq = 0;
    try {
        bd_seq = store_.next();
    } catch (const core::Error& error) {
        log(LogLevel::error, std::string("Sparkplug: ") + error.what());
        reconnect_.schedule();
        return;
    }
    apply(session_.connecting(bd_seq));
    client_->select_server(server_);
    client_->connect();
}

void EdgeNode::stop(std::function<void()> done) {
    stopping_ = true;
    reconnect_.cancel();
    sweep_timer_.cancel();
    tick_timer_.cancel();
    stop_done_ = std::move(done);
    const session::Actions actions = session_.stop(now());
    const bool disconnects = std::any_of(actions.begin(), actions.end(), [](const session::Action& a) {
        return std::holds_alternative<session::Disconnect>(a);
    });
    apply(actions);
    if (!disconnects) {
        client_->disconnect(disconnect_timeout, [this, alive = std::weak_ptr<bool>(alive_)] {
            const auto flag = alive.lock();
            if (flag && *flag && stop_done_) std::exchange(stop_done_, {})();
        });
    }
}

void EdgeNode::on_message(const mqtt::Message& message) {
    if (stopping_) return;
    const session::NodeIdentity& node = settings_.session.node;
    if (message.topic == session::node_topic(node, session::MessageType::ncmd)) {
        on_ncmd(message.payload);
        return;
    }
    for (Device& device : devices_) {
        if (message.topic == session::device_topic(node, session::MessageType::dcmd, device.source->name())) {
            on_dcmd(device, message.payload);
            return;
        }
    }
    if (!settings_.session.primary_host_id.empty()) {
        apply(session_.host_state(message.topic, message.payload, now()));
        arm_tick();
    }
}

void EdgeNode::refuse(const std::string& what, const std::string& why) {
    ++counters_.commands_refused;
    log(LogLevel::warning, "Sparkplug: " + what + " refused, nothing written: " + why);
}

void EdgeNode::on_ncmd(const std::string& payload) {
    const sparkplug::CommandResult decoded = sparkplug::decode_command(payload);
    if (!decoded.ok()) return refuse("an NCMD", decoded.error);
    bool rebirth = false;
    for (const sparkplug::CommandMetric& metric : decoded.command->metrics) {
        const bool named = metric.metric.name && *metric.metric.name == session::rebirth_metric_name;
        const auto* value = std::get_if<bool>(&metric.value);
        if (!named || value == nullptr) {
            return refuse("an NCMD", std::string("only ") + std::string(session::rebirth_metric_name) +
                                         " (Boolean) is a node command");
        }
        rebirth = rebirth || *value;
    }
    if (!rebirth) return;
    log(LogLevel::info, "Sparkplug: rebirth requested by the host (NCMD)");
    apply(session_.rebirth(now()));
}

void EdgeNode::on_dcmd(Device& device, const std::string& payload) {
    mqtt::DeviceSource& source = *device.source;
    const std::string what = "a DCMD for device " + core::quoted(source.name());
    const sparkplug::CommandResult decoded = sparkplug::decode_command(payload);
    if (!decoded.ok()) return refuse(what, core::quoted(decoded.error));
    if (!source.commands_enabled()) return refuse(what, "its commands are off (mqtt_commands: false)");
    if (running_commands_ >= settings_.max_running_commands) {
        return refuse(what, std::to_string(running_commands_) + " DCMDs are still being executed; send it again later");
    }
    const engine::OperationSet operations = source.operations();
    DcmdPlan plan = plan_dcmd(catalogue_, source.name(), *decoded.command, device.arguments,
                              engine::field_setters(operations));
    if (!plan.ok()) return refuse(what, plan.error);
    // Every command parsed and checked before anything is sent: all or nothing.
    const mqtt::SourceState state = source.state();
    std::vector<protocol::Request> requests;
    for (const nlohmann::json& command : plan.commands) {
        const mqtt::ParseResult parsed =
            mqtt::parse_command(command.dump(), source.operations(), state.raw, source.points());
        if (const auto* error = std::get_if<mqtt::CommandError>(&parsed)) {
            return refuse(what, "op " + core::quoted(command.value("op", "")) + ": " + error->message);
        }
        for (const protocol::Request& request : std::get<mqtt::ParsedCommand>(parsed).requests) {
            requests.push_back(request);
        }
    }
    // Parameters are kept and shown to the host.
    std::vector<Metric> echoed;
    const session::Instant at = now();
    for (auto& [metric, value] : plan.arguments) {
        device.arguments[metric->name] = value;
        Metric m;
        if (settings_.session.aliases) {
            m.alias = metric->alias;
        } else {
            m.name = metric->name;
        }
        m.value = value;
        m.timestamp = at.utc_ms;
        echoed.push_back(std::move(m));
    }
    if (!echoed.empty()) apply(session_.device_changed(source.name(), std::move(echoed), at));
    if (requests.empty()) {
        ++counters_.commands_accepted;
        return;
    }
    ++running_commands_;
    mqtt::run_command(io_, device.source, std::move(requests),
                      [this, what, alive = std::weak_ptr<bool>(alive_)](const mqtt::CommandOutcome& outcome) {
                          const auto flag = alive.lock();
                          if (!flag || !*flag) return;
                          --running_commands_;
                          if (outcome.ok) {
                              ++counters_.commands_accepted;
                              return;
                          }
                          ++counters_.commands_refused;
                          log(LogLevel::warning, "Sparkplug: " + what + " failed on the device (" + outcome.error +
                                                     "): " + outcome.message);
                      });
}

}  // namespace fieldbridge::northbound::sparkplug_node
