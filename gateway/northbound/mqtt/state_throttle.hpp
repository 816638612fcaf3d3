#pragma once
/// @file state_throttle.hpp
/// When a device's state is published (spec §6): on a change that matters, no sooner
/// than `min_interval` after the previous publication, and at least every
/// `heartbeat`. A numeric field whose change since the last PUBLISHED value is below
/// its deadband is not a change (so a slow drift is published once it adds up).
/// Online and quality changes always count; raw registers count only for a device
/// without decoded fields (a generic Modbus device). Pure: the caller passes times.
#include <map>
#include <optional>
#include <string>

#include "engine/transaction.hpp"
#include "northbound/mqtt/device_source.hpp"

namespace fieldbridge::northbound::mqtt {

struct ThrottleSettings {
    engine::Duration min_interval = std::chrono::milliseconds{200};
    engine::Duration heartbeat = std::chrono::seconds{60};
    std::map<std::string, double, std::less<>> deadband;  ///< field name -> smallest change published
};

/// True when the field @p after differs from @p before by more than its deadband in
/// @p deadband allows (a list: its largest element change); any change without one.
[[nodiscard]] bool field_differs(const engine::Field& before, const engine::Field& after,
                                 const std::map<std::string, double, std::less<>>& deadband);

/// True when @p now differs from @p published by more than the deadbands allow.
[[nodiscard]] bool state_differs(const SourceState& published, const SourceState& now,
                                 const std::map<std::string, double, std::less<>>& deadband);

class StateThrottle {
public:
    explicit StateThrottle(ThrottleSettings settings) : settings_(std::move(settings)) {}

    /// Whether @p state should be published at @p now.
    [[nodiscard]] bool due(const SourceState& state, engine::TimePoint now) const;
    /// The earliest time a publication may become due without a new state (a
    /// change held back by min_interval, or the heartbeat); nullopt before the first.
    [[nodiscard]] std::optional<engine::TimePoint> next_check(const SourceState& state) const;
    /// Records that @p state was published at @p now.
    void published(SourceState state, engine::TimePoint now);
    /// Forgets what was published (the broker came back: publish everything again).
    void reset() noexcept { last_.reset(); }

private:
    ThrottleSettings settings_;
    std::optional<SourceState> last_;
    engine::TimePoint last_time_{};
};

}  // namespace fieldbridge::northbound::mqtt
