"""MQTT over TLS and MQTT 5 through the real gateway and a private mosquitto with a
TLS listener (issue 15): the CA, broker and client certificates are made by the test
with openssl. A verified broker with a client certificate required; verification
off against a broker whose CA the gateway does not know; a wrong CA and a missing
client certificate refused with an error that says what to check; MQTT 5 connect and
its last will."""

import os
import subprocess

import gatewaylib
from test_mqtt import MqttCell, TIMEOUT, topic

TLS_MQTT_CONFIG = """\
mqtt:
  uri: ssl://127.0.0.1:{{mqtt_port}}
  qos: 1
  keep_alive: 2s
  heartbeat: 30s
  min_interval: 100ms
  diag_period: 60s
  version: "{version}"
  reconnect_backoff: {{{{initial: 200ms, max: 1s}}}}
  tls:
{tls}"""


def openssl(*args, cwd):
    done = subprocess.run(["openssl"] + list(args), cwd=cwd, capture_output=True, text=True,
                          timeout=gatewaylib.IO_TIMEOUT * 4)
    if done.returncode != 0:
        raise AssertionError("openssl %s failed: %s" % (" ".join(args), done.stderr))


def make_ca(directory, name):
    openssl("req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes", "-days", "2",
            "-subj", "/CN=%s" % name, "-keyout", name + ".key", "-out", name + ".pem", cwd=directory)


def make_certificate(directory, name, ca, extensions):
    """name.pem / name.key signed by ca, with the given X509v3 extension lines."""
    with open(os.path.join(directory, name + ".ext"), "w", encoding="utf-8") as f:
        f.write(extensions)
    openssl("req", "-new", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes",
            "-subj", "/CN=%s" % name, "-keyout", name + ".key", "-out", name + ".csr", cwd=directory)
    openssl("x509", "-req", "-in", name + ".csr", "-CA", ca + ".pem", "-CAkey", ca + ".key", "-CAcreateserial",
            "-days", "2", "-extfile", name + ".ext", "-out", name + ".pem", cwd=directory)


class TlsCell(MqttCell):

    def setUp(self):
        super().setUp()
        # mosquitto started as root runs as user mosquitto: it must be able to read them.
        os.chmod(self.tmp, 0o711)
        os.mkdir(self.path("tls"), 0o755)
        tls = self.path("tls")
        make_ca(tls, "ca")
        make_ca(tls, "other-ca")
        make_certificate(tls, "broker", "ca", "subjectAltName=IP:127.0.0.1,DNS:localhost\n"
                                              "extendedKeyUsage=serverAuth\n")
        make_certificate(tls, "client", "ca", "extendedKeyUsage=clientAuth\n")
        for name in os.listdir(tls):
            os.chmod(os.path.join(tls, name), 0o644)
        self.mqtt_client_args = ("--cafile", self.tls("ca.pem"), "--cert", self.tls("client.pem"),
                                 "--key", self.tls("client.key"))

    def tls(self, name):
        return os.path.join(self.tmp, "tls", name)

    def start_tls(self, tls, require_certificate=True, version="3.1.1"):
        """Broker with a TLS listener; the gateway's mqtt.tls is the dict tls (file
        names in the test directory)."""
        self.broker_listener = ("allow_anonymous true\ncafile %s\ncertfile %s\nkeyfile %s\nrequire_certificate %s\n"
                                % (self.tls("ca.pem"), self.tls("broker.pem"), self.tls("broker.key"),
                                   "true" if require_certificate else "false"))
        lines = "".join("    %s: %s\n" % (key, self.tls(value) if key.endswith("_file") else value)
                        for key, value in tls.items())
        self.mqtt_config = TLS_MQTT_CONFIG.format(version=version, tls=lines)
        self.start()

    def assert_online(self):
        self.assertIsNotNone(self.sub.wait_message(topic("status"), lambda p: p == "online", TIMEOUT),
                             self.gateway.text())
        self.wait_state("gripper-1", lambda s: s["online"], TIMEOUT)

    def assert_refused(self, *fragments):
        """The gateway logs the failed TLS connection with fragments, and never publishes."""
        found = self.gateway.wait_line(lambda line: "MQTT: cannot connect to the broker" in line, TIMEOUT)
        self.assertIsNotNone(found, self.gateway.text())
        for fragment in fragments:
            self.assertIn(fragment, found[1])
        self.assertEqual(self.sub.messages(topic("status")), [])


class VerifiedTls(TlsCell):

    def test_verified_broker_and_client_certificate(self):
        self.start_tls({"ca_file": "ca.pem", "cert_file": "client.pem", "key_file": "client.key"})
        self.assert_online()
        # Commands come in over the same TLS connection.
        self.command("gripper-1", {"op": "stop"})

    def test_verification_off_accepts_a_broker_signed_by_an_unknown_ca(self):
        self.start_tls({"ca_file": "other-ca.pem", "verify": "false"}, require_certificate=False)
        self.assert_online()


class RefusedTls(TlsCell):

    def test_wrong_ca_is_refused_with_a_clear_error(self):
        self.start_tls({"ca_file": "other-ca.pem", "cert_file": "client.pem", "key_file": "client.key"})
        self.assert_refused("must be signed by a CA in mqtt.tls.ca_file (%s)" % self.tls("other-ca.pem"))

    def test_missing_client_certificate_is_refused_with_a_clear_error(self):
        self.start_tls({"ca_file": "ca.pem"})
        self.assert_refused("a broker that requires client certificates needs mqtt.tls.cert_file and "
                            "mqtt.tls.key_file")


class Mqtt5(TlsCell):

    def test_mqtt5_connect_state_command_and_last_will(self):
        self.mqtt_client_args += ("-V", "mqttv5")
        self.start_tls({"ca_file": "ca.pem", "cert_file": "client.pem", "key_file": "client.key"}, version="5")
        self.assert_online()
        self.command("gripper-1", {"op": "stop"})
        self.assert_will_on_sigkill()


if __name__ == "__main__":
    gatewaylib.main()
