// What the log says about a failed connection to a TLS broker.
#include <doctest/doctest.h>

#include "northbound/mqtt/tls_advice.hpp"

namespace fieldbridge::northbound::mqtt {
namespace {

[[nodiscard]] bool has(const std::string& text, const char* part) { return text.find(part) != std::string::npos; }

TEST_CASE("verification on: the CA file (or the system store) and the host name") {
    config::MqttTlsConfig tls;
    CHECK(has(tls_failure_advice(tls), "signed by a CA in the system trust store (or set mqtt.tls.ca_file)"));
    tls.ca_file = "/etc/fieldbridge/ca.pem";
    const auto advice = tls_failure_advice(tls);
    CHECK(has(advice, "signed by a CA in mqtt.tls.ca_file (/etc/fieldbridge/ca.pem) and name the host of mqtt.uri"));
    CHECK(has(advice, "needs mqtt.tls.cert_file and mqtt.tls.key_file"));
}

TEST_CASE("verification off: only the client certificate") {
    config::MqttTlsConfig tls;
    tls.verify = false;
    tls.cert_file = "/etc/fieldbridge/client.pem";
    const auto advice = tls_failure_advice(tls);
    CHECK_FALSE(has(advice, "ca_file"));
    CHECK(has(advice, "mqtt.tls.cert_file (/etc/fieldbridge/client.pem) must be signed by a CA the broker trusts"));
}

}  // namespace
}  // namespace fieldbridge::northbound::mqtt
