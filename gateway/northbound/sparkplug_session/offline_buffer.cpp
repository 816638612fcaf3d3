#include "northbound/sparkplug_session/offline_buffer.hpp"

#include <string>
#include <utility>
#include <variant>

namespace fieldbridge::northbound::sparkplug_session {

namespace {

std::size_t value_bytes(const sparkplug::Value& value) noexcept {
    if (const auto* text = std::get_if<std::string>(&value)) return text->size();
    return 0;
}

}  // namespace

std::size_t buffered_bytes(const BufferedData& data) noexcept {
    std::size_t bytes = sizeof(BufferedData) + data.device.size();
    for (const sparkplug::Metric& metric : data.metrics) {
        bytes += sizeof(sparkplug::Metric) + (metric.name ? metric.name->size() : 0) + value_bytes(metric.value);
        for (const sparkplug::Property& property : metric.properties) {
            bytes += sizeof(sparkplug::Property) + property.key.size() + value_bytes(property.value);
        }
    }
    return bytes;
}

void OfflineBuffer::push(BufferedData data) {
    const std::size_t size = buffered_bytes(data);
    if (size > max_bytes_ || max_messages_ == 0) {
        ++dropped_;
        return;
    }
    while (!items_.empty() && (items_.size() + 1 > max_messages_ || bytes_ + size > max_bytes_)) {
        bytes_ -= items_.front().bytes;
        items_.pop_front();
        ++dropped_;
    }
    items_.push_back(Item{std::move(data), size});
    bytes_ += size;
}

std::vector<BufferedData> OfflineBuffer::take_all() {
    std::vector<BufferedData> out;
    out.reserve(items_.size());
    for (Item& item : items_) out.push_back(std::move(item.data));
    items_.clear();
    bytes_ = 0;
    return out;
}

}  // namespace fieldbridge::northbound::sparkplug_session
