#pragma once
/// @file fault_plan.hpp
/// Fault injection for one simulated bus: parsed fault specifications and the
/// per-bus plan that decides, frame by frame, which faults hit a reply. Pure and
/// deterministic: all randomness comes from the plan's own generator, seeded from
/// --seed, so a run with the same seed and the same traffic injects the same faults.
///
/// Spec grammar (command line `--fault` and control socket `fault`):
///   TARGET:KIND[:ARG][:WHEN]
///   TARGET = BUS | BUS@ADDRESS            (bus name = file name of its pty link)
///   KIND   = drop | corrupt-crc | truncate | delay:MS | garbage | echo
///          | dead | revive | unplug:MS
///   WHEN   = always (default) | P (probability, 0 < P <= 1) | next=N | off

#include <chrono>
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "protocol/bytes.hpp"

namespace fieldbridge::sim::runtime {

enum class FaultKind : std::uint8_t {
    drop,         ///< the device's reply is not sent
    corrupt_crc,  ///< the reply's CRC is damaged
    truncate,     ///< only the first half of the reply is sent
    delay,        ///< the reply is sent `duration` later
    garbage,      ///< random bytes are sent ahead of the reply
    echo,         ///< bus-wide: every request is echoed back (2-wire adapter)
    dead,         ///< state: the device stops answering until revive
    revive,       ///< state: a dead device answers again
    unplug,       ///< action: the pty vanishes for `duration`, then comes back
};

[[nodiscard]] std::string_view to_string(FaultKind kind) noexcept;

struct FaultTrigger {
    enum class Mode : std::uint8_t { always, probability, next, off };
    Mode mode = Mode::always;
    double probability = 1.0;     ///< Mode::probability
    std::uint64_t remaining = 0;  ///< Mode::next: frames still to hit
    bool operator==(const FaultTrigger&) const = default;
};

struct FaultSpec {
    std::string bus;
    std::optional<std::uint8_t> address;  ///< nullopt: bus-wide
    FaultKind kind = FaultKind::drop;
    std::chrono::nanoseconds duration{};  ///< delay and unplug
    FaultTrigger trigger;
    bool operator==(const FaultSpec&) const = default;
};

/// Parses one fault spec (colons or blanks between fields). Throws SimError saying
/// which part is wrong and what was expected.
[[nodiscard]] FaultSpec parse_fault_spec(std::string_view text);

/// What happens to one reply.
struct ReplyFaults {
    bool drop = false;
    bool corrupt_crc = false;
    bool truncate = false;
    bool garbage = false;
    std::chrono::nanoseconds delay{};
};

class FaultPlan {
public:
    explicit FaultPlan(std::uint64_t seed) : rng_(seed) {}

    /// Adds or replaces the rule for (address, kind); WHEN = off removes it. Only the
    /// reply faults and echo are rules; dead/revive/unplug are actions on the bus.
    void set(const FaultSpec& spec);
    /// Removes every rule (nullopt) or the rules of one device address.
    void clear(std::optional<std::uint8_t> address);

    /// Decides the faults for a reply by the device at @p address: its own rules and
    /// the bus-wide ones. A `next=N` rule counts down only when it hits.
    [[nodiscard]] ReplyFaults decide_reply(std::uint8_t address);
    /// Decides whether one received frame (or discarded run of bytes) is echoed.
    [[nodiscard]] bool decide_echo();
    /// 1 to 8 random bytes, never '>' so that an ASCII reply behind them still frames.
    [[nodiscard]] protocol::Bytes random_garbage();

    [[nodiscard]] nlohmann::json describe() const;
    [[nodiscard]] bool empty() const noexcept { return rules_.empty(); }

private:
    struct Rule {
        std::optional<std::uint8_t> address;
        FaultKind kind = FaultKind::drop;
        std::chrono::nanoseconds duration{};
        FaultTrigger trigger;
    };
    [[nodiscard]] bool fire(Rule& rule);

    std::vector<Rule> rules_;
    std::mt19937_64 rng_;
};

}  // namespace fieldbridge::sim::runtime
