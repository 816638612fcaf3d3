#include "engine/transaction.hpp"

namespace fieldbridge::engine {

const char* to_string(OutcomeStatus status) noexcept {
    switch (status) {
        case OutcomeStatus::ok: return "ok";
        case OutcomeStatus::timeout: return "timeout";
        case OutcomeStatus::expired: return "expired";
        case OutcomeStatus::queue_full: return "queue_full";
        case OutcomeStatus::line_down: return "line_down";
        case OutcomeStatus::device_offline: return "device_offline";
        case OutcomeStatus::cancelled: return "cancelled";
        case OutcomeStatus::broadcast_sent: return "broadcast_sent";
        case OutcomeStatus::invalid_request: return "invalid_request";
        case OutcomeStatus::bad_reply: return "bad_reply";
    }
    return "unknown";
}

}  // namespace fieldbridge::engine
