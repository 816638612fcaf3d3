#pragma once
/// @file mqtt_uri.hpp
/// The broker URI of the MQTT section: scheme://host[:port][/path].

#include <cstdint>
#include <string>
#include <string_view>

#include "config/parsed.hpp"

namespace fieldbridge::config {

struct MqttUri {
    std::string scheme;      ///< tcp, ssl, ws or wss
    std::string host;        ///< IPv6 without brackets
    std::uint16_t port = 0;  ///< the scheme's default when the URI has none
    std::string path;        ///< ws / wss only, e.g. "/mqtt"; empty otherwise

    /// ssl:// or wss://.
    [[nodiscard]] bool tls() const noexcept { return scheme == "ssl" || scheme == "wss"; }
};

/// Default ports: tcp 1883, ssl 8883, ws 80, wss 443.
[[nodiscard]] Parsed<MqttUri> parse_mqtt_uri(std::string_view text);

}  // namespace fieldbridge::config
