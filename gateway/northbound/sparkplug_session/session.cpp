#include "northbound/sparkplug_session/session.hpp"

#include <algorithm>
#include <utility>

#include "core/log_text.hpp"
#include "northbound/sparkplug_session/messages.hpp"

namespace fieldbridge::northbound::sparkplug_session {

namespace {

using sparkplug::Metric;

/// A STATE payload is quoted in a warning up to this many bytes.
constexpr std::size_t quoted_payload_bytes = 120;

/// Whether @p a and @p b are the same metric: the same name, or (a data message
/// names by alias only) the same alias.
bool same_metric(const Metric& a, const Metric& b) {
    if (a.name && b.name) return *a.name == *b.name;
    return a.alias && b.alias && *a.alias == *b.alias;
}

/// Takes the values of @p changed into the matching metrics of @p into; with
/// @p append, a metric @p into lacks is added (the pending list), otherwise ignored.
void merge_values(std::vector<Metric>& into, const std::vector<Metric>& changed, bool append) {
    for (const Metric& change : changed) {
        const auto found = std::find_if(into.begin(), into.end(), [&](const Metric& m) { return same_metric(m, change); });
        if (found == into.end()) {
            if (append) into.push_back(change);
            continue;
        }
        if (append) {
            *found = change;
        } else {
            found->value = change.value;
            found->timestamp = change.timestamp;
        }
    }
}

}  // namespace

Session::Session(SessionSettings settings, std::vector<Metric> node_metrics, std::vector<DeviceMetrics> devices)
    : settings_(std::move(settings)),
      node_metrics_(std::move(node_metrics)),
      buffer_(settings_.offline_max_messages, settings_.offline_max_bytes) {
    devices_.reserve(devices.size());
    for (DeviceMetrics& device : devices) devices_.push_back(Device{std::move(device.name), std::move(device.metrics), false, false, {}, {}});
}

Session::Device* Session::find(std::string_view name) {
    const auto found = std::find_if(devices_.begin(), devices_.end(), [&](const Device& d) { return d.name == name; });
    return found == devices_.end() ? nullptr : &*found;
}

bool Session::connected() const noexcept { return phase_ == Phase::waiting_for_host || phase_ == Phase::online; }

void Session::publish(Actions& out, std::string topic, sparkplug::Payload payload, int qos) {
    // tck-id-payloads-sequence-num-incrementing: +1 on every message but NDEATH, 255 -> 0.
    payload.seq = seq_;
    seq_ = static_cast<std::uint8_t>(seq_ + 1);
    out.emplace_back(Publish{std::move(topic), std::move(payload), qos, false});
}

Actions Session::connecting(std::uint8_t bd_seq) {
    if (phase_ == Phase::stopped) return {};
    forget_session();
    bd_seq_ = bd_seq;
    phase_ = Phase::connecting;
    // tck-id-message-flow-edge-node-birth-publish-will-message(-topic, -payload-bdSeq,
    // -qos, -will-retained); tck-id-topics-ndeath-payload, tck-id-topics-ndeath-seq.
    return {SetWill{node_topic(settings_.node, MessageType::ndeath), ndeath_payload(bd_seq, std::nullopt), 1, false}};
}

void Session::subscriptions(Actions& out) const {
    // tck-id-message-flow-edge-node-ncmd-subscribe: NCMD at QoS 1, before the NBIRTH.
    out.emplace_back(Subscribe{node_topic(settings_.node, MessageType::ncmd), 1});
    // tck-id-message-flow-device-dcmd-subscribe: each device's DCMD at QoS 1.
    for (const Device& device : devices_) {
        out.emplace_back(Subscribe{device_topic(settings_.node, MessageType::dcmd, device.name), 1});
    }
    if (!settings_.primary_host_id.empty()) {
        out.emplace_back(Subscribe{host_state_topic(settings_.primary_host_id), 1});
    }
}

Actions Session::connected(const Instant& now) {
    Actions out;
    if (phase_ != Phase::connecting) return out;
    subscriptions(out);
    if (settings_.primary_host_id.empty()) {
        births(out, now);
    } else {
        // tck-id-message-flow-edge-node-birth-publish-phid-wait,
        // tck-id-operational-behavior-edge-node-birth-sequence-wait.
        phase_ = Phase::waiting_for_host;
    }
    return out;
}

void Session::births(Actions& out, const Instant& now) {
    // tck-id-topics-nbirth-seq-num: the NBIRTH's seq is 0; tck-id-topics-nbirth-bdseq-matching
    // and tck-id-operational-behavior-data-commands-rebirth-action-3: the will's bdSeq.
    seq_ = 0;
    publish(out, node_topic(settings_.node, MessageType::nbirth),
            nbirth_payload(bd_seq_.value_or(0), node_metrics_, settings_.aliases, now.utc_ms));
    // tck-id-message-flow-device-birth-publish-nbirth-wait: DBIRTHs after the NBIRTH.
    for (Device& device : devices_) {
        device.born = false;
        device.pending.clear();
        device.last_data.reset();
        if (device.online) dbirth(out, device, now);
    }
    phase_ = Phase::online;
    replay(out, now);
}

void Session::dbirth(Actions& out, Device& device, const Instant& now) {
    device.pending.clear();
    publish(out, device_topic(settings_.node, MessageType::dbirth, device.name),
            dbirth_payload(device.metrics, settings_.aliases, now.utc_ms));
    device.born = true;
}

void Session::ddeath(Actions& out, Device& device, const Instant& now) {
    // tck-id-operational-behavior-device-ddeath.
    publish(out, device_topic(settings_.node, MessageType::ddeath, device.name), ddeath_payload(now.utc_ms));
    device.born = false;
    device.pending.clear();
    device.last_data.reset();
}

void Session::ddata(Actions& out, Device& device, std::vector<Metric> metrics, const Instant& now) {
    publish(out, device_topic(settings_.node, MessageType::ddata, device.name),
            data_payload(std::move(metrics), settings_.aliases, false, now.utc_ms));
    device.last_data = now.mono;
}

void Session::flush(Actions& out, Device& device, const Instant& now) {
    if (device.pending.empty()) return;
    ddata(out, device, std::exchange(device.pending, {}), now);
}

void Session::replay(Actions& out, const Instant& now) {
    for (BufferedData& data : buffer_.take_all()) {
        if (data.device.empty()) {
            publish(out, node_topic(settings_.node, MessageType::ndata),
                    data_payload(std::move(data.metrics), settings_.aliases, true, now.utc_ms));
            continue;
        }
        const Device* device = find(data.device);
        if (device == nullptr || !device->born) {
            buffer_.count_dropped();  // a DDATA needs its device's DBIRTH in this session
            continue;
        }
        publish(out, device_topic(settings_.node, MessageType::ddata, data.device),
                data_payload(std::move(data.metrics), settings_.aliases, true, now.utc_ms));
    }
}

void Session::buffer(std::string device, std::vector<Metric> metrics, std::uint64_t produced_ms) {
    buffer_.push(BufferedData{std::move(device), std::move(metrics), produced_ms});
}

void Session::forget_session() {
    host_.reset();
    for (Device& device : devices_) {
        device.born = false;
        device.last_data.reset();
    }
}

Actions Session::connection_lost() {
    if (phase_ != Phase::stopped) lose_session();
    return {};
}

void Session::lose_session() {
    // Changes held back by the rate rule were produced: they wait with the rest.
    for (Device& device : devices_) {
        if (device.pending.empty()) continue;
        const std::uint64_t produced = device.pending.front().timestamp.value_or(0);
        buffer(device.name, std::exchange(device.pending, {}), produced);
    }
    forget_session();
    phase_ = Phase::disconnected;
}

void Session::end_session(Actions& out, const Instant& now, bool next_server) {
    // tck-id-operational-behavior-edge-node-intentional-disconnect-ndeath and -packet:
    // the node's own NDEATH (QoS 1, like the will), then DISCONNECT.
    out.emplace_back(Publish{node_topic(settings_.node, MessageType::ndeath),
                             ndeath_payload(bd_seq_.value_or(0), now.utc_ms), 1, false});
    out.emplace_back(Disconnect{next_server});
}

Actions Session::host_state(std::string_view topic, std::string_view payload, const Instant& now) {
    Actions out;
    // tck-id-message-flow-edge-node-birth-publish-phid-wait-id: only our host's topic.
    if (settings_.primary_host_id.empty() || topic != host_state_topic(settings_.primary_host_id) || !connected()) {
        return out;
    }
    const HostStateParse parsed = parse_host_state(payload);
    if (!parsed.state) {
        ++counters_.malformed_host_states;
        out.emplace_back(Warning{"Sparkplug: the STATE of primary host " + core::quoted(settings_.primary_host_id) +
                                 " is ignored: " + parsed.problem + "; payload " +
                                 core::quoted(payload.substr(0, quoted_payload_bytes)) +
                                 (payload.size() > quoted_payload_bytes ? " (cut)" : "")});
        return out;
    }
    switch (host_.observe(*parsed.state)) {
    case HostVerdict::stale:
        ++counters_.stale_host_states;
        break;
    case HostVerdict::unchanged:
        break;
    case HostVerdict::online:
        if (phase_ == Phase::waiting_for_host) births(out, now);
        break;
    case HostVerdict::offline:
        // tck-id-message-flow-edge-node-birth-publish-phid-offline,
        // tck-id-operational-behavior-primary-application-state-with-multiple-servers-walk.
        end_session(out, now, /*next_server=*/true);
        lose_session();
        break;
    }
    return out;
}

Actions Session::unknown_device(std::string_view name) {
    ++counters_.unknown_devices;
    return {Warning{"Sparkplug: no configured device is named " + core::quoted(name) +
                    " (an event for it is ignored; a reload that is still being applied?)"}};
}

Actions Session::device_online(std::string_view name, std::vector<Metric> metrics, const Instant& now) {
    Device* device = find(name);
    if (device == nullptr) return unknown_device(name);
    Actions out;
    device->metrics = std::move(metrics);
    device->online = true;
    if (phase_ == Phase::online) dbirth(out, *device, now);
    return out;
}

Actions Session::device_offline(std::string_view name, const Instant& now) {
    Device* device = find(name);
    if (device == nullptr) return unknown_device(name);
    Actions out;
    device->online = false;
    if (phase_ == Phase::online && device->born) {
        flush(out, *device, now);  // the last values it had, then its death
        ddeath(out, *device, now);
    }
    return out;
}

Actions Session::device_changed(std::string_view name, std::vector<Metric> changed, const Instant& now) {
    Device* device = find(name);
    if (device == nullptr) return unknown_device(name);
    Actions out;
    if (changed.empty()) return out;
    for (Metric& metric : changed) {
        if (!metric.timestamp) metric.timestamp = now.utc_ms;
    }
    merge_values(device->metrics, changed, /*append=*/false);
    if (!device->online) return out;
    if (phase_ != Phase::online) {
        buffer(device->name, std::move(changed), now.utc_ms);
        return out;
    }
    if (!device->born) return out;
    // tck-id-operational-behavior-data-publish-dbirth-change: DDATA on change only; no
    // sooner than min_interval after the device's previous DDATA (held changes merge).
    const bool due = !device->last_data || now.mono - *device->last_data >= settings_.min_interval;
    merge_values(device->pending, changed, /*append=*/true);
    if (due) flush(out, *device, now);
    return out;
}

Actions Session::node_changed(std::vector<Metric> changed, const Instant& now) {
    Actions out;
    if (changed.empty()) return out;
    for (Metric& metric : changed) {
        if (!metric.timestamp) metric.timestamp = now.utc_ms;
    }
    merge_values(node_metrics_, changed, /*append=*/false);
    if (phase_ != Phase::online) {
        buffer({}, std::move(changed), now.utc_ms);
        return out;
    }
    // tck-id-operational-behavior-data-publish-nbirth-change.
    publish(out, node_topic(settings_.node, MessageType::ndata),
            data_payload(std::move(changed), settings_.aliases, false, now.utc_ms));
    return out;
}

Actions Session::rebirth(const Instant& now) {
    Actions out;
    // Waiting for the host, the births come when it is online; disconnected, at the next session.
    if (phase_ != Phase::online) return out;
    // tck-id-operational-behavior-data-commands-rebirth-action-1 and -2: data stops
    // (held changes are in the DBIRTHs' values), the whole birth sequence again.
    ++counters_.rebirths;
    births(out, now);
    return out;
}

Actions Session::reload(std::vector<Metric> node_metrics, std::vector<DeviceMetrics> devices, const Instant& now) {
    Actions out;
    const bool node_changed_definitions = !same_definitions(node_metrics_, node_metrics);
    node_metrics_ = std::move(node_metrics);
    const bool live = phase_ == Phase::online;
    // Devices that are gone: their death, and no more commands for them.
    for (Device& old : devices_) {
        const bool kept = std::any_of(devices.begin(), devices.end(), [&](const DeviceMetrics& d) { return d.name == old.name; });
        if (kept) continue;
        if (live && old.born) ddeath(out, old, now);
        if (connected()) out.emplace_back(Unsubscribe{device_topic(settings_.node, MessageType::dcmd, old.name)});
    }
    std::vector<Device> next;
    next.reserve(devices.size());
    std::vector<std::size_t> redefined;  // devices born before whose metrics changed
    for (DeviceMetrics& incoming : devices) {
        Device* old = find(incoming.name);
        if (old == nullptr) {
            if (connected()) out.emplace_back(Subscribe{device_topic(settings_.node, MessageType::dcmd, incoming.name), 1});
            next.push_back(Device{std::move(incoming.name), std::move(incoming.metrics), false, false, {}, {}});
            continue;
        }
        if (!same_definitions(old->metrics, incoming.metrics)) {
            old->metrics = std::move(incoming.metrics);
            if (live && old->born) redefined.push_back(next.size());
        }
        next.push_back(std::move(*old));
    }
    devices_ = std::move(next);
    if (!live) return out;
    if (node_changed_definitions) {
        ++counters_.rebirths;
        births(out, now);  // the whole node: NBIRTH and every DBIRTH
        return out;
    }
    for (const std::size_t index : redefined) {
        Device& device = devices_[index];
        ddeath(out, device, now);
        if (device.online) dbirth(out, device, now);
    }
    return out;
}

Actions Session::tick(const Instant& now) {
    Actions out;
    if (phase_ != Phase::online) return out;
    for (Device& device : devices_) {
        if (device.pending.empty() || !device.born) continue;
        if (device.last_data && now.mono - *device.last_data < settings_.min_interval) continue;
        flush(out, device, now);
    }
    return out;
}

std::optional<SteadyClock::time_point> Session::next_deadline() const {
    std::optional<SteadyClock::time_point> earliest;
    if (phase_ != Phase::online) return earliest;
    for (const Device& device : devices_) {
        if (device.pending.empty() || !device.born) continue;
        const SteadyClock::time_point due = device.last_data ? *device.last_data + settings_.min_interval
                                                             : SteadyClock::time_point{};
        if (!earliest || due < *earliest) earliest = due;
    }
    return earliest;
}

Actions Session::stop(const Instant& now) {
    Actions out;
    if (connected()) end_session(out, now, /*next_server=*/false);
    phase_ = Phase::stopped;
    return out;
}

}  // namespace fieldbridge::northbound::sparkplug_session
