#include "northbound/mqtt/tls_advice.hpp"

namespace fieldbridge::northbound::mqtt {

std::string tls_failure_advice(const config::MqttTlsConfig& tls) {
    std::string advice = "TLS: if the broker is up, it refused the handshake or this gateway refused the broker: ";
    if (tls.verify) {
        advice += "the broker's certificate must be signed by a CA in " +
                  (tls.ca_file.empty() ? std::string("the system trust store (or set mqtt.tls.ca_file)")
                                       : "mqtt.tls.ca_file (" + tls.ca_file + ")") +
                  " and name the host of mqtt.uri (mqtt.tls.verify: false skips this check); ";
    }
    advice += tls.cert_file.empty()
                  ? "a broker that requires client certificates needs mqtt.tls.cert_file and mqtt.tls.key_file"
                  : "the client certificate in mqtt.tls.cert_file (" + tls.cert_file +
                        ") must be signed by a CA the broker trusts";
    return advice + "; the broker's log names the reason";
}

}  // namespace fieldbridge::northbound::mqtt
