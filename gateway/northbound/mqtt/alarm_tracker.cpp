#include "northbound/mqtt/alarm_tracker.hpp"

#include <algorithm>
#include <string>

namespace fieldbridge::northbound::mqtt {

namespace {

[[nodiscard]] engine::Alarm comm_loss_alarm() {
    return engine::Alarm{comm_loss_code, "the device does not answer (offline)", engine::Severity::critical,
                         "communication"};
}

[[nodiscard]] engine::Alarm notice_alarm(const engine::DeviceNotice& notice) {
    return engine::Alarm{exception_status_code, notice.text, engine::Severity::warning,
                         "exception status 0x" + [&] {
                             const char* digits = "0123456789ABCDEF";
                             return std::string{digits[notice.code >> 4], digits[notice.code & 0x0F]};
                         }()};
}

[[nodiscard]] bool same_identity(const engine::Alarm& a, const engine::Alarm& b) {
    return a.code == b.code && a.source == b.source;
}

}  // namespace

void AlarmTracker::notice(const engine::DeviceNotice& notice, engine::TimePoint now) {
    if (notice.code == 0) {
        notice_.reset();
        return;
    }
    notice_ = notice;
    notice_until_ = now + settings_.notice_hold;
    notice_pending_ = true;
}

std::vector<engine::Alarm> AlarmTracker::wanted(const std::vector<engine::Alarm>& profile_alarms, bool online,
                                                engine::TimePoint now) {
    std::vector<engine::Alarm> want = profile_alarms;
    if (!first_update_) {
        first_update_ = now;
    }
    ever_online_ = ever_online_ || online;
    if (!online && (ever_online_ || now - *first_update_ >= settings_.startup_grace)) {
        comm_lost_ = true;
        online_since_.reset();
    } else if (comm_lost_) {
        if (!online_since_) {
            online_since_ = now;
        }
        if (now - *online_since_ >= settings_.comm_clear_hold) {
            comm_lost_ = false;
            online_since_.reset();
        }
    }
    if (comm_lost_) {
        want.push_back(comm_loss_alarm());
    }
    if (notice_ && now >= notice_until_) {
        notice_.reset();
    }
    if (notice_) {
        want.push_back(notice_alarm(*notice_));
    }
    return want;
}

std::vector<AlarmEvent> AlarmTracker::update(const std::vector<engine::Alarm>& profile_alarms, bool online,
                                             engine::TimePoint now) {
    const std::vector<engine::Alarm> want = wanted(profile_alarms, online, now);
    std::vector<AlarmEvent> events;
    std::vector<ActiveAlarm> next;
    next.reserve(want.size());
    for (const ActiveAlarm& a : active_) {
        const bool kept = std::any_of(want.begin(), want.end(),
                                      [&](const engine::Alarm& w) { return same_identity(w, a.alarm); });
        if (!kept) {
            events.push_back({AlarmTransition::cleared, a.alarm, now});
        }
    }
    for (const engine::Alarm& w : want) {
        const auto old = std::find_if(active_.begin(), active_.end(),
                                      [&](const ActiveAlarm& a) { return same_identity(w, a.alarm); });
        // A repeated notice is a new event even while the previous one is active.
        const bool renewed = notice_pending_ && w.code == exception_status_code;
        if (old == active_.end() || renewed) {
            if (old != active_.end()) {
                events.push_back({AlarmTransition::cleared, old->alarm, now});
            }
            events.push_back({AlarmTransition::raised, w, now});
            next.push_back({w, now});
        } else {
            // Same alarm: keep its start time, take the newest text.
            next.push_back({w, old->since});
        }
    }
    notice_pending_ = false;
    active_ = std::move(next);
    return events;
}

std::optional<engine::TimePoint> AlarmTracker::next_deadline() const noexcept {
    std::optional<engine::TimePoint> at;
    const auto consider = [&](engine::TimePoint t) {
        if (!at || t < *at) {
            at = t;
        }
    };
    if (comm_lost_ && online_since_) {
        consider(*online_since_ + settings_.comm_clear_hold);
    }
    if (!comm_lost_ && !ever_online_ && first_update_) {
        consider(*first_update_ + settings_.startup_grace);
    }
    if (notice_) {
        consider(notice_until_);
    }
    return at;
}

}  // namespace fieldbridge::northbound::mqtt
