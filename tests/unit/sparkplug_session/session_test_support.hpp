#pragma once
/// @file session_test_support.hpp
/// A small edge node for the session tests: two devices, one node metric, and
/// helpers that pick actions of one kind out of what the session returns.
#include <chrono>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "northbound/sparkplug_session/session.hpp"

namespace fieldbridge::test::sparkplug_session {

namespace sp = fieldbridge::northbound::sparkplug;
namespace ss = fieldbridge::northbound::sparkplug_session;

inline sp::Metric metric(std::string name, std::uint64_t alias, double value,
                         sp::DataType type = sp::DataType::float64) {
    sp::Metric m;
    m.name = std::move(name);
    m.alias = alias;
    m.datatype = type;
    m.value = value;
    return m;
}

/// A changed value, named as the catalogue names it (name and alias).
inline sp::Metric change(std::string name, std::uint64_t alias, double value) {
    sp::Metric m;
    m.name = std::move(name);
    m.alias = alias;
    m.value = value;
    return m;
}

inline std::vector<sp::Metric> xeg_metrics(double position = 1.5) {
    return {metric("position_mm", 10, position), metric("speed_pct", 11, 50)};
}
inline std::vector<sp::Metric> wtec_metrics() { return {metric("force_pct", 20, 30)}; }
inline std::vector<sp::Metric> node_metrics() {
    return {metric("Properties/Software Version", 1, 0, sp::DataType::string)};
}

inline ss::SessionSettings settings(std::string primary_host = {}) {
    ss::SessionSettings s;
    s.node = {"plant1", "gw-7"};
    s.primary_host_id = std::move(primary_host);
    s.min_interval = std::chrono::milliseconds{200};
    return s;
}

inline ss::Session make_session(ss::SessionSettings s = settings()) {
    return ss::Session(std::move(s), node_metrics(), {{"xeg1", xeg_metrics()}, {"wtec1", wtec_metrics()}});
}

/// A test clock: monotonic and wall time advance together.
struct Clock {
    std::chrono::steady_clock::time_point mono{std::chrono::seconds{1000}};
    std::uint64_t utc = 1'700'000'000'000;
    ss::Instant now() const { return {mono, utc}; }
    ss::Instant advance(std::chrono::milliseconds by) {
        mono += by;
        utc += static_cast<std::uint64_t>(by.count());
        return now();
    }
};

template <class T>
std::vector<T> only(const ss::Actions& actions) {
    std::vector<T> out;
    for (const ss::Action& action : actions) {
        if (const T* item = std::get_if<T>(&action)) out.push_back(*item);
    }
    return out;
}

inline std::vector<std::string> topics(const ss::Actions& actions) {
    std::vector<std::string> out;
    for (const ss::Action& action : actions) {
        std::visit(
            [&](const auto& item) {
                using T = std::decay_t<decltype(item)>;
                if constexpr (std::is_same_v<T, ss::Publish>) out.push_back("pub " + item.topic);
                if constexpr (std::is_same_v<T, ss::Subscribe>) out.push_back("sub " + item.topic);
                if constexpr (std::is_same_v<T, ss::Unsubscribe>) out.push_back("unsub " + item.topic);
                if constexpr (std::is_same_v<T, ss::SetWill>) out.push_back("will " + item.topic);
                if constexpr (std::is_same_v<T, ss::Disconnect>) out.push_back(item.next_server ? "disconnect next" : "disconnect");
                if constexpr (std::is_same_v<T, ss::Warning>) out.push_back("warning");
            },
            action);
    }
    return out;
}

inline std::vector<std::uint64_t> seqs(const ss::Actions& actions) {
    std::vector<std::uint64_t> out;
    for (const ss::Publish& p : only<ss::Publish>(actions)) out.push_back(p.payload.seq.value_or(999));
    return out;
}

/// The metric named @p name in @p payload, or nullptr.
inline const sp::Metric* find(const sp::Payload& payload, std::string_view name) {
    for (const sp::Metric& m : payload.metrics) {
        if (m.name && *m.name == name) return &m;
    }
    return nullptr;
}

/// A session connected with @p bd_seq and born (no primary host): births dropped.
inline ss::Session online_session(Clock& clock, std::uint8_t bd_seq = 3) {
    ss::Session session = make_session();
    static_cast<void>(session.device_online("xeg1", xeg_metrics(), clock.now()));
    static_cast<void>(session.device_online("wtec1", wtec_metrics(), clock.now()));
    static_cast<void>(session.connecting(bd_seq));
    static_cast<void>(session.connected(clock.now()));
    return session;
}

}  // namespace fieldbridge::test::sparkplug_session
