#include "northbound/sparkplug_session/host_state.hpp"

#include <nlohmann/json.hpp>

namespace fieldbridge::northbound::sparkplug_session {

namespace {

using nlohmann::json;

HostStateParse problem(std::string text) { return HostStateParse{std::nullopt, std::move(text)}; }

bool is_legacy(std::string_view payload) { return payload == "ONLINE" || payload == "OFFLINE"; }

}  // namespace

HostStateParse parse_host_state(std::string_view payload) {
    if (payload.size() > max_host_state_bytes) {
        return problem("the STATE payload has " + std::to_string(payload.size()) + " bytes, more than the " +
                       std::to_string(max_host_state_bytes) + " a Sparkplug 3.0 STATE can need");
    }
    if (is_legacy(payload)) {
        return problem("the STATE payload is the Sparkplug 2.x text " + std::string{payload} +
                       "; fieldbridge follows Sparkplug 3.0 hosts only (JSON {\"online\":bool,\"timestamp\":ms}): "
                       "update the host application or remove sparkplug.primary_host_id");
    }
    const json document = json::parse(payload, nullptr, /*allow_exceptions=*/false);
    if (document.is_discarded()) return problem("the STATE payload is not JSON");
    if (!document.is_object()) return problem("the STATE payload is not a JSON object");
    const auto online = document.find("online");
    if (online == document.end() || !online->is_boolean()) {
        return problem("the STATE payload has no boolean \"online\"");
    }
    const auto timestamp = document.find("timestamp");
    if (timestamp == document.end() || !timestamp->is_number_unsigned()) {
        return problem("the STATE payload has no non-negative integer \"timestamp\"");
    }
    return HostStateParse{HostState{online->get<bool>(), timestamp->get<std::uint64_t>()}, {}};
}

HostVerdict HostTracker::observe(const HostState& state) noexcept {
    if (seen_ && state.timestamp < last_) return HostVerdict::stale;
    const bool first = !seen_;
    seen_ = true;
    last_ = state.timestamp;
    if (!first && state.online == online_) return HostVerdict::unchanged;
    online_ = state.online;
    return online_ ? HostVerdict::online : HostVerdict::offline;
}

}  // namespace fieldbridge::northbound::sparkplug_session
