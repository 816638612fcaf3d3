#pragma once
/// @file sparkplug_seen.hpp
/// What the Sparkplug benchmark's subscriber saw (mosquitto_sub on spBv1.0/#), read
/// from the tests' own decoder's output (tests/support/sparkplug_decode.py --lines: one
/// JSON object a message), independent of the gateway's encoder: messages by type, the
/// polled devices' DDATA by timestamp, and each (round, device, point) change found in
/// a DDATA metric, through the aliases of the DBIRTHs before it.
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace fieldbridge::bench::sparkplug_cell {

struct Seen {
    std::uint64_t messages = 0;
    std::uint64_t decode_errors = 0;
    std::map<std::string, std::uint64_t> by_type;  ///< NBIRTH, DBIRTH, DDATA, NDATA, ...
    /// DDATA of the polled devices: (payload timestamp ms, metrics) per message.
    std::vector<std::pair<std::int64_t, std::uint64_t>> ddata;
    std::uint64_t other_ddata_metrics = 0;  ///< line-e's devices
    std::uint64_t unmapped_metrics = 0;     ///< an alias no DBIRTH named
    /// How often each change was published, by change_key().
    std::unordered_map<std::uint64_t, std::uint32_t> published;
};

/// The key of the change of round @p round (mod 65536) to point @p i of device @p d.
[[nodiscard]] inline std::uint64_t change_key(std::uint64_t round, int d, int i) {
    return ((round & 0xFFFFu) << 16) | (static_cast<std::uint64_t>(d) << 6) | static_cast<unsigned>(i);
}

/// Reads the decoder's output @p decoded.
[[nodiscard]] Seen read_subscriber(const std::filesystem::path& decoded);

}  // namespace fieldbridge::bench::sparkplug_cell
