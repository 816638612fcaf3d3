#include "config/config.hpp"

#include <algorithm>

namespace fieldbridge::config {

std::string_view to_string(RuleAction action) noexcept {
    switch (action) {
        case RuleAction::allow: return "allow";
        case RuleAction::deny: return "deny";
    }
    return "unknown";
}

std::string_view to_string(MqttVersion version) noexcept {
    switch (version) {
        case MqttVersion::v3_1_1: return "3.1.1";
        case MqttVersion::v5: return "5";
    }
    return "unknown";
}

Range<std::uint8_t> address_range(DeviceType type) noexcept {
    switch (type) {
        case DeviceType::hiwin_xeg: return {1, 15};     // seed 001 section 2.2
        case DeviceType::excd203mb: return {1, 254};    // seed 002 section 5: 0x01-0xFE
        case DeviceType::wtec_rtu:                      // seed 003: "01" to "253"
        case DeviceType::wtec_ascii: return {1, 253};
        case DeviceType::modbus: return {1, 247};       // Modbus serial line V1.02 section 2.2
    }
    return {1, 247};
}

core::BusAddress broadcast_address(DeviceType type) noexcept {
    // Seed 002 section 5: "廣播地址: 0xFF"; every other manual uses the Modbus 0.
    return core::BusAddress{type == DeviceType::excd203mb ? std::uint8_t{0xFF} : std::uint8_t{0}};
}

bool has_register_pairs(DeviceType type) noexcept {
    return type == DeviceType::excd203mb || type == DeviceType::modbus;
}

namespace {

template <class T>
[[nodiscard]] bool empty_or_contains(const std::vector<T>& list, T value) noexcept {
    return list.empty() || std::find(list.begin(), list.end(), value) != list.end();
}

}  // namespace

bool AccessRule::matches(const IpAddress& client, core::UnitId unit, core::FunctionCode function,
                         std::optional<RegisterRange> request) const noexcept {
    const bool client_matches =
        clients.empty() || std::any_of(clients.begin(), clients.end(), [&](const Cidr& c) { return c.contains(client); });
    if (!client_matches || !empty_or_contains(units, unit) || !empty_or_contains(functions, function)) {
        return false;
    }
    if (!registers) {
        return true;
    }
    if (!request) {
        return false;
    }
    if (action == RuleAction::deny) {
        return request->from <= registers->to && registers->from <= request->to;  // overlap
    }
    return registers->from <= request->from && request->to <= registers->to;  // containment
}

bool ModbusTcpConfig::client_allowed(const IpAddress& client) const noexcept {
    return allow.empty() || std::any_of(allow.begin(), allow.end(), [&](const Cidr& c) { return c.contains(client); });
}

RuleAction ModbusTcpConfig::decide(const IpAddress& client, core::UnitId unit, core::FunctionCode function,
                                   std::optional<RegisterRange> request) const noexcept {
    for (const auto& rule : rules) {
        if (rule.matches(client, unit, function, request)) {
            return rule.action;
        }
    }
    return RuleAction::allow;
}

unsigned LineConfig::bits_per_character() const noexcept {
    return 1U + data_bits + (parity == Parity::none ? 0U : 1U) + stop_bits;
}

std::chrono::nanoseconds LineConfig::character_time() const noexcept {
    if (baud == 0) {
        return std::chrono::nanoseconds{0};
    }
    return std::chrono::nanoseconds{(std::int64_t{bits_per_character()} * 1'000'000'000 + baud - 1) / baud};
}

bool MqttConfig::uses_tls() const noexcept {
    return !uris.empty() && (uris.front().starts_with("ssl://") || uris.front().starts_with("wss://"));
}

bool SparkplugConfig::uses_tls() const noexcept {
    return std::any_of(servers.begin(), servers.end(), [](const std::string& uri) { return uri.starts_with("ssl://"); });
}

}  // namespace fieldbridge::config
