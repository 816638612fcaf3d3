#pragma once
/// @file host_state.hpp
/// The primary host application's STATE message (Sparkplug 3.0, "Topics and
/// Messages", STATE): a retained JSON payload `{"online":bool,"timestamp":ms}` on
/// `spBv1.0/STATE/<host_id>`, and the edge node's rules for reading it. Pure: bytes in,
/// a verdict out; the caller logs the warnings.
///
/// A legacy Sparkplug 2.x payload (`ONLINE` / `OFFLINE`, published by older hosts on
/// `STATE/<host_id>`) is not accepted: it carries no timestamp, so the ordering rules
/// below cannot be applied to it. It is reported with a warning that says so.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace fieldbridge::northbound::sparkplug_session {

/// A STATE payload larger than this is refused unread (a real one is about 45 bytes).
inline constexpr std::size_t max_host_state_bytes = 1024;

struct HostState {
    bool online = false;
    std::uint64_t timestamp = 0;  ///< ms since the Unix epoch, UTC
    bool operator==(const HostState&) const = default;
};

/// A STATE payload read: the state, or what is wrong with it (for the operator).
struct HostStateParse {
    std::optional<HostState> state;
    std::string problem;  ///< empty when state is set
};

/// Reads @p payload (tck-id-host-topic-phid-birth-payload): a JSON object whose
/// `online` is a boolean and whose `timestamp` is a non-negative integer; other keys
/// are ignored. Anything else, and more than max_host_state_bytes, is a problem.
[[nodiscard]] HostStateParse parse_host_state(std::string_view payload);

/// What a STATE message means for the edge node.
enum class HostVerdict {
    online,         ///< the host is online (it was not, or this is the first STATE)
    offline,        ///< the host went offline: NDEATH, disconnect, walk to the next server
    unchanged,      ///< the same state again
    stale,          ///< older than the last STATE accepted: ignored
};

/// The primary host's state as one MQTT session of the edge node has seen it
/// (tck-id-message-flow-edge-node-birth-publish-phid-wait-online,
/// tck-id-message-flow-edge-node-birth-publish-phid-wait-timestamp): the first
/// STATE of a session is taken as it is; a later one counts only when its timestamp
/// is not older than the last one accepted; an offline STATE takes the host offline
/// when its timestamp is at least the one of the online STATE it answers
/// (tck-id-message-flow-edge-node-birth-publish-phid-offline). A new session starts
/// over (reset()): each server keeps its own retained STATE.
class HostTracker {
public:
    [[nodiscard]] HostVerdict observe(const HostState& state) noexcept;
    [[nodiscard]] bool online() const noexcept { return online_; }
    void reset() noexcept { *this = HostTracker{}; }

private:
    bool seen_ = false;
    bool online_ = false;
    std::uint64_t last_ = 0;
};

}  // namespace fieldbridge::northbound::sparkplug_session
