#pragma once
/// @file alarm_tracker.hpp
/// The active alarms of one device and their raise / clear events (spec §6). Three
/// kinds of sources:
///  - the profile's alarms (status codes, alarm bits, ralarm, R6 alarm number): the
///    set is diffed against the previous one;
///  - communication loss: raised (`comm_loss`, critical) as soon as the device is
///    offline (the line already waited for `offline_after` consecutive timeouts),
///    cleared only once it has been online again for `comm_clear_hold`, so a device
///    that flaps does not flood the topic. A device never seen online since the
///    gateway started gets `startup_grace` first (the first poll, the upstream's
///    first connection), so a start-up is not reported as a communication loss;
///  - device notices (XEG FC07 exception status after an exception 0x04): the device
///    says it once, so the alarm (`exception_status`, warning) stays active for
///    `notice_hold` after the last notice, then clears. A notice with code 0 ("no
///    error") clears it at once.
/// Pure: the caller passes times and asks for the next deadline.
#include <optional>
#include <vector>

#include "engine/profiles/device_profile.hpp"
#include "engine/transaction.hpp"
#include "northbound/mqtt/payloads.hpp"

namespace fieldbridge::northbound::mqtt {

struct AlarmSettings {
    engine::Duration comm_clear_hold = std::chrono::seconds{5};
    engine::Duration notice_hold = std::chrono::seconds{60};
    engine::Duration startup_grace = std::chrono::seconds{5};
};

inline constexpr const char* comm_loss_code = "comm_loss";
inline constexpr const char* exception_status_code = "exception_status";

class AlarmTracker {
public:
    explicit AlarmTracker(AlarmSettings settings = {}) : settings_(settings) {}

    /// Takes the profile's alarms and the online flag at @p now; returns what was
    /// raised and cleared (raises after clears, both in alarm order).
    [[nodiscard]] std::vector<AlarmEvent> update(const std::vector<engine::Alarm>& profile_alarms, bool online,
                                                 engine::TimePoint now);
    /// A notice from the device (call update() afterwards for the events).
    void notice(const engine::DeviceNotice& notice, engine::TimePoint now);

    /// When update() must be called again even if nothing changes (a hold ends).
    [[nodiscard]] std::optional<engine::TimePoint> next_deadline() const noexcept;
    /// Profile alarms first (in the profile's order), then comm_loss, then the notice.
    [[nodiscard]] const std::vector<ActiveAlarm>& active() const noexcept { return active_; }

private:
    [[nodiscard]] std::vector<engine::Alarm> wanted(const std::vector<engine::Alarm>& profile_alarms, bool online,
                                                    engine::TimePoint now);

    AlarmSettings settings_;
    std::vector<ActiveAlarm> active_;
    bool comm_lost_ = false;
    bool ever_online_ = false;
    std::optional<engine::TimePoint> first_update_;  ///< start of the startup grace
    std::optional<engine::TimePoint> online_since_;  ///< while comm_lost_ and online
    std::optional<engine::DeviceNotice> notice_;
    engine::TimePoint notice_until_{};
    bool notice_pending_ = false;  ///< a notice arrived since the last update
};

}  // namespace fieldbridge::northbound::mqtt
