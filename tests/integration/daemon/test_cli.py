"""The command line of the real binary: --check-config, --version, usage errors,
and a gateway refusing to start on a bad configuration."""

import os
import re
import unittest

import daemon_harness as h


class CommandLine(h.DaemonTestCase, unittest.TestCase):

    def test_check_config_valid(self):
        path = self.config(h.CONFIG_TWO_LINES)
        result = self.run_binary(["--check-config", path])
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(result.stdout,
                         "%s: configuration is valid (2 lines, 3 devices, MQTT disabled)\n" % path)
        self.assertEqual(result.stderr, "")

    def test_check_config_project_examples(self):
        # The demo and the commented example shipped with the project are valid.
        for name in ("demo.yaml", "fieldbridge.example.yaml"):
            path = os.path.join(self.config_dir, name)
            with self.subTest(name=name):
                result = self.run_binary(["--check-config", path])
                self.assertEqual(result.returncode, 0, result.stderr)
                self.assertTrue(result.stdout.startswith(path + ": configuration is valid ("), result.stdout)

    def test_check_config_invalid_lists_every_problem(self):
        path = self.config(h.CONFIG_BROKEN)
        result = self.run_binary(["--check-config", path])
        self.assertEqual(result.returncode, 2)
        self.assertEqual(result.stdout, "")
        lines = result.stderr.splitlines()
        self.assertRegex(lines[0], "^" + re.escape(path) + r":3:3: gateway\.colour: ")
        self.assertRegex(lines[1], "^" + re.escape(path) + r":9:11: lines\[0\]\.baud: ")
        self.assertEqual(lines[-1], "%s: 2 problems found; the configuration is not valid" % path)

    def test_check_config_missing_file(self):
        path = os.path.join(self.tmp, "absent.yaml")
        result = self.run_binary(["--check-config", path])
        self.assertEqual(result.returncode, 2)
        self.assertIn(path + ": cannot open the configuration file", result.stderr)

    def test_version_and_help(self):
        result = self.run_binary(["--version"])
        self.assertEqual(result.returncode, 0)
        self.assertRegex(result.stdout, r"^fieldbridge \d+\.\d+\.\d+\n$")
        result = self.run_binary(["--help"])
        self.assertEqual(result.returncode, 0)
        self.assertIn("--check-config", result.stdout)

    def test_usage_errors_exit_64(self):
        for args in ([], ["--bogus"], ["--config"], ["--config", "a", "--check-config", "b"],
                     ["--config", "a", "--log-level", "loud"]):
            with self.subTest(args=args):
                result = self.run_binary(args)
                self.assertEqual(result.returncode, 64, result.stderr)
                self.assertIn("--help", result.stderr)

    def test_run_with_invalid_config_exits_2_without_ready(self):
        notify = self.notify_socket()
        path = self.config(h.CONFIG_BROKEN)
        gateway = self.start(["--config", path], env=h.clean_environment({"NOTIFY_SOCKET": notify.path}))
        self.assertEqual(gateway.wait_exit(), 2)
        stderr = gateway.stderr_text()
        self.assertIn("%s:3:3: gateway.colour: " % path, stderr)
        self.assertIn("cannot start: the configuration %s" % path, stderr)
        notify.drain()
        self.assertFalse([m for m in notify.messages if m.startswith("READY=1")], notify.messages)

    def test_run_with_missing_config_exits_2(self):
        path = os.path.join(self.tmp, "absent.yaml")
        gateway = self.start(["--config", path])
        self.assertEqual(gateway.wait_exit(), 2)
        self.assertIn(path + ": cannot open the configuration file", gateway.stderr_text())


if __name__ == "__main__":
    CommandLine.binary, CommandLine.config_dir = h.parse_arguments()
    unittest.main()
