#pragma once
/// @file tls_advice.hpp
/// What an operator can do about a failed connection to a TLS broker: Paho reports
/// only "MQTT error [-1]" for a refused certificate, so the log names the settings
/// to check. Pure.
#include <string>

#include "config/config.hpp"

namespace fieldbridge::northbound::mqtt {

/// "TLS: ...; check mqtt.tls.ca_file ..." for the settings in @p tls.
[[nodiscard]] std::string tls_failure_advice(const config::MqttTlsConfig& tls);

}  // namespace fieldbridge::northbound::mqtt
