#include "northbound/mqtt/inbound_gate.hpp"

namespace fieldbridge::northbound::mqtt {

bool InboundGate::admit(std::size_t bytes) noexcept {
    const std::lock_guard lock(mutex_);
    if (messages_ + 1 > max_messages_ || bytes_ + bytes > max_bytes_) {
        ++dropped_;
        return false;
    }
    ++messages_;
    bytes_ += bytes;
    return true;
}

void InboundGate::release(std::size_t bytes) noexcept {
    const std::lock_guard lock(mutex_);
    if (messages_ > 0) --messages_;
    bytes_ -= bytes < bytes_ ? bytes : bytes_;
}

std::uint64_t InboundGate::take_unreported() noexcept {
    const std::lock_guard lock(mutex_);
    const std::uint64_t count = dropped_ - reported_;
    reported_ = dropped_;
    return count;
}

std::uint64_t InboundGate::dropped() const noexcept {
    const std::lock_guard lock(mutex_);
    return dropped_;
}

}  // namespace fieldbridge::northbound::mqtt
