#include "config/mqtt_uri.hpp"

#include <array>
#include <charconv>

#include "config/net_address.hpp"

namespace fieldbridge::config {

namespace {

struct Scheme {
    std::string_view name;
    std::uint16_t default_port;
};
constexpr std::array<Scheme, 4> schemes{{{"tcp", 1883}, {"ssl", 8883}, {"ws", 80}, {"wss", 443}}};

}  // namespace

Parsed<MqttUri> parse_mqtt_uri(std::string_view text) {
    using Result = Parsed<MqttUri>;
    const std::string expected =
        "expected tcp://host:1883, ssl://host:8883, ws://host:80/path or wss://host:443/path";
    const std::string quoted = "'" + std::string(text) + "'";
    const auto separator = text.find("://");
    if (separator == std::string_view::npos) {
        return Result::fail(quoted + " has no scheme; " + expected);
    }
    MqttUri uri;
    uri.scheme = std::string(text.substr(0, separator));
    const Scheme* scheme = nullptr;
    for (const auto& s : schemes) {
        if (uri.scheme == s.name) {
            scheme = &s;
        }
    }
    if (scheme == nullptr) {
        return Result::fail(quoted + " has the unsupported scheme '" + uri.scheme + "'; " + expected);
    }
    std::string_view rest = text.substr(separator + 3);
    const auto slash = rest.find('/');
    if (slash != std::string_view::npos) {
        uri.path = std::string(rest.substr(slash));
        rest = rest.substr(0, slash);
        if (!uri.path.empty() && uri.path != "/" && (uri.scheme == "tcp" || uri.scheme == "ssl")) {
            return Result::fail(quoted + " has a path, which only ws:// and wss:// URIs may have; " + expected);
        }
    }
    std::string_view host = rest;
    std::string_view port;
    if (!rest.empty() && rest.front() == '[') {
        const auto close = rest.find(']');
        if (close == std::string_view::npos) {
            return Result::fail(quoted + " has an unterminated [IPv6] host; " + expected);
        }
        host = rest.substr(1, close - 1);
        const std::string_view after = rest.substr(close + 1);
        if (!after.empty()) {
            if (after.front() != ':') {
                return Result::fail(quoted + " has text after the [IPv6] host; " + expected);
            }
            port = after.substr(1);
        }
        if (!parse_ip_address(host)) {
            return Result::fail(quoted + ": '" + std::string(host) + "' is not an IPv6 address; " + expected);
        }
    } else {
        const auto colon = rest.find(':');
        if (colon != std::string_view::npos) {
            host = rest.substr(0, colon);
            port = rest.substr(colon + 1);
        }
        if (!is_valid_host(host)) {
            return Result::fail(quoted + " has no valid host; " + expected);
        }
    }
    uri.host = std::string(host);
    uri.port = scheme->default_port;
    if (!port.empty() || (rest.find(':') != std::string_view::npos && rest.front() != '[')) {
        unsigned value = 0;
        const auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), value);
        if (port.empty() || ec != std::errc{} || end != port.data() + port.size() || value < 1 || value > 65535) {
            return Result::fail(quoted + " has an invalid port '" + std::string(port) + "'; expected 1..65535");
        }
        uri.port = static_cast<std::uint16_t>(value);
    }
    return Result::ok(std::move(uri));
}

}  // namespace fieldbridge::config
