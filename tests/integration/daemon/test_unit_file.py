"""deploy/fieldbridge.service: the settings the daemon relies on, and
systemd-analyze's opinion of the unit when the tool is installed."""

import os
import shutil
import subprocess
import unittest

import daemon_harness as h


def parse_unit(path):
    """{section: {key: [values in order]}}; continuation lines are not used in the unit."""
    sections, current = {}, None
    with open(path, encoding="utf-8") as f:
        for raw in f:
            line = raw.strip()
            if not line or line.startswith(("#", ";")):
                continue
            if line.startswith("[") and line.endswith("]"):
                current = sections.setdefault(line[1:-1], {})
                continue
            key, _, value = line.partition("=")
            current.setdefault(key.strip(), []).append(value.strip())
    return sections


class UnitFile(h.DaemonTestCase, unittest.TestCase):

    def setUp(self):
        super().setUp()
        self.unit_path = os.path.join(self.config_dir, os.pardir, "deploy", "fieldbridge.service")
        self.unit = parse_unit(self.unit_path)

    def value(self, key, section="Service"):
        values = self.unit.get(section, {}).get(key)
        self.assertIsNotNone(values, "%s= missing in [%s]" % (key, section))
        return values[-1]

    def test_service_type_and_commands(self):
        self.assertEqual(self.value("Type"), "notify")
        self.assertEqual(self.value("NotifyAccess"), "main")
        self.assertEqual(self.value("ExecStart"), "/usr/bin/fieldbridge --config /etc/fieldbridge/fieldbridge.yaml")
        self.assertEqual(self.unit["Service"]["ExecReload"],
                         ["/usr/bin/fieldbridge --check-config /etc/fieldbridge/fieldbridge.yaml",
                          "/bin/kill -HUP $MAINPID"])
        self.assertEqual(self.value("WatchdogSec"), "10")
        self.assertEqual(self.value("Restart"), "on-failure")
        # Exit codes of gateway/daemon/exit_codes.hpp that a restart cannot fix.
        self.assertEqual(self.value("RestartPreventExitStatus").split(), ["2", "64"])
        self.assertEqual(self.value("WantedBy", "Install"), "multi-user.target")

    def test_user_and_hardening(self):
        expected = {
            "User": "fieldbridge", "Group": "fieldbridge", "SupplementaryGroups": "dialout",
            "AmbientCapabilities": "CAP_NET_BIND_SERVICE", "CapabilityBoundingSet": "CAP_NET_BIND_SERVICE",
            "NoNewPrivileges": "yes", "ProtectSystem": "strict", "ProtectHome": "yes", "PrivateTmp": "yes",
            "ProtectKernelTunables": "yes", "RestrictAddressFamilies": "AF_UNIX AF_INET AF_INET6",
            "DevicePolicy": "closed",
        }
        for key, value in expected.items():
            with self.subTest(key=key):
                self.assertEqual(self.value(key), value)
        self.assertIn("char-ttyUSB rw", self.unit["Service"]["DeviceAllow"])
        self.assertNotIn("PrivateDevices", self.unit["Service"])  # it would hide the serial ports

    def copy_for_analysis(self):
        """The unit with the built binary in place of /usr/bin/fieldbridge, which
        systemd-analyze verify requires to exist."""
        with open(self.unit_path, encoding="utf-8") as f:
            text = f.read().replace("/usr/bin/fieldbridge", self.binary)
        return h.write_file(self.tmp, "fieldbridge.service", text)

    @unittest.skipUnless(shutil.which("systemd-analyze"), "systemd-analyze is not installed")
    def test_systemd_analyze_verify_is_silent(self):
        # --man=no: the Documentation= man pages are installed by the package, not here
        # (tests/package/test-package.sh verifies the installed unit with them).
        result = subprocess.run(["systemd-analyze", "verify", "--man=no", self.copy_for_analysis()],
                                capture_output=True, text=True, timeout=h.TIMEOUT)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(result.stderr + result.stdout, "")

    @unittest.skipUnless(shutil.which("systemd-analyze"), "systemd-analyze is not installed")
    def test_systemd_analyze_security_exposure_is_ok(self):
        # Exposure 0.0-10.0; the threshold is in tenths. 2.0 is the top of "OK".
        result = subprocess.run(["systemd-analyze", "security", "--offline=yes", "--threshold=20",
                                 self.copy_for_analysis()], capture_output=True, text=True, timeout=h.TIMEOUT)
        self.assertEqual(result.returncode, 0, result.stdout[-2000:] + result.stderr)


if __name__ == "__main__":
    UnitFile.binary, UnitFile.config_dir = h.parse_arguments()
    unittest.main()
