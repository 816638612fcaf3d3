"""System test of `fieldbridge scan`: the real binary scans fieldbridge-sim buses
(pseudo-terminals) and its snippet is checked by `fieldbridge --check-config`.

Run: test_scan.py --fieldbridge PATH --sim PATH (PYTHONPATH must hold simlib.py).
Python 3 standard library only; every process is bounded by a timeout."""

import os
import subprocess
import sys

import simlib

FIELDBRIDGE = None
SCAN_TIMEOUT = 120.0  # sanitizer builds on a busy 2-core machine


def devices_of(snippet):
    """The devices of the snippet as {address: {key: value}}, read line by line: the
    snippet's format is fixed (scan_report.cpp), and the stdlib has no YAML reader;
    --check-config is the real YAML check."""
    devices = {}
    current = None
    for line in snippet.splitlines():
        text = line.split("#", 1)[0].rstrip()
        if not text.strip():
            continue
        if text.startswith("  - "):
            current = {}
            text = "    " + text[4:]
        if text.startswith("    ") and not text.startswith("      ") and current is not None:
            key, _, value = text.strip().partition(":")
            current[key] = value.strip()
            if key == "address":
                devices[int(value)] = current
    return devices


class ScanTest(simlib.SimTestCase):

    def scan(self, *args):
        return subprocess.run([FIELDBRIDGE, "scan"] + [str(a) for a in args], capture_output=True,
                              text=True, timeout=SCAN_TIMEOUT)

    def start_buses(self):
        self.start("--bus", self.path("line") + ":hiwin-xeg@2,excd203mb@3,wtec-ascii@5",
                   "--bus", self.path("line2") + ":wtec-rtu@1")

    def check_config(self, port, snippet):
        body = "".join("    " + l + "\n" if l else "\n" for l in snippet.splitlines())
        config = ("gateway:\n  id: scan-test\nlines:\n  - name: line-a\n    port: %s\n    baud: 115200\n%s"
                  % (port, body))
        path = self.path("scan.yaml")
        with open(path, "w") as f:
            f.write(config)
        return subprocess.run([FIELDBRIDGE, "--check-config", path], capture_output=True, text=True,
                              timeout=SCAN_TIMEOUT), config

    def test_finds_every_device_on_a_shared_bus(self):
        self.start_buses()
        result = self.scan("--port", self.path("line"), "--from", 1, "--to", 10)
        self.assertEqual(result.returncode, 0, result.stderr)
        found = devices_of(result.stdout)
        self.assertEqual(sorted(found), [2, 3, 5], result.stdout)
        self.assertEqual(found[2]["type"], "hiwin-xeg")
        self.assertEqual(found[3]["type"], "excd203mb")
        self.assertEqual(found[5]["type"], "wtec-ascii")
        for address, device in found.items():
            self.assertEqual(device["unit_id"], str(address))
            self.assertEqual(device["name"], "%s-%d" % (device["type"], address))
        self.assertEqual(found[5]["stroke"], "20000")
        self.assertIn("XEG-32", result.stdout)          # the model read from 0x0600
        self.assertIn("Cstep [A]1.62", result.stdout)   # the firmware text of `A`
        self.assertIn("address 2: hiwin-xeg", result.stderr)
        self.assertIn("3 devices found", result.stderr)

        check, config = self.check_config(self.path("line"), result.stdout)
        self.assertEqual(check.returncode, 0, "config:\n%s\nstdout:\n%s\nstderr:\n%s"
                         % (config, check.stdout, check.stderr))
        self.assertIn("3 devices", check.stdout)

    def test_finds_the_wtec_in_rtu_mode(self):
        self.start_buses()
        result = self.scan("--port", self.path("line2"), "--to", 4, "--timeout", 30)
        self.assertEqual(result.returncode, 0, result.stderr)
        found = devices_of(result.stdout)
        self.assertEqual(list(found), [1], result.stdout)
        self.assertEqual(found[1]["type"], "wtec-rtu")
        check, config = self.check_config(self.path("line2"), result.stdout)
        self.assertEqual(check.returncode, 0, "config:\n%s\nstderr:\n%s" % (config, check.stderr))

    def test_a_definition_identify_read_names_a_generic_device(self):
        shipped = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir,
                                                os.pardir, "config", "devices"))
        self.start("--definitions", shipped, "--bus", self.path("line4") + ":example-thermostat@7",
                   "--control", self.path("sim.sock"))
        # example-thermostat identifies by its firmware string starting with "TH".
        self.assertEqual(self.control("device 7 set firmware TH-1.2"), "ok")
        result = self.scan("--port", self.path("line4"), "--from", 6, "--to", 9, "--definitions", shipped)
        self.assertEqual(result.returncode, 0, result.stderr)
        found = devices_of(result.stdout)
        self.assertEqual(sorted(found), [7], result.stdout)
        self.assertEqual(found[7]["type"], "example-thermostat")
        self.assertEqual(found[7]["name"], "example-thermostat-7")
        self.assertIn("address 7: example-thermostat, device definition example-thermostat: its identify read "
                      "(holding 0x0020) reads the expected values", result.stderr)
        body = "".join("    " + l + "\n" if l else "\n" for l in result.stdout.splitlines())
        path = self.path("scan-definitions.yaml")
        with open(path, "w") as f:
            f.write("gateway:\n  id: scan-test\ndefinitions: [%s]\nlines:\n  - name: line-a\n    port: %s\n%s"
                    % (shipped, self.path("line4"), body))
        check = subprocess.run([FIELDBRIDGE, "--check-config", path], capture_output=True, text=True,
                               timeout=SCAN_TIMEOUT)
        self.assertEqual(check.returncode, 0, check.stderr)

    def test_every_ascii_station_answering_one_query_is_found(self):
        # Both gripper replies to `$` come back to back, often in one read.
        self.start("--bus", self.path("line3") + ":wtec-ascii@5,wtec-ascii@9,hiwin-xeg@12")
        result = self.scan("--port", self.path("line3"), "--from", 4, "--to", 12)
        self.assertEqual(result.returncode, 0, result.stderr)
        found = devices_of(result.stdout)
        self.assertEqual(sorted(found), [5, 9, 12], result.stdout)
        self.assertEqual([found[a]["type"] for a in (5, 9, 12)], ["wtec-ascii", "wtec-ascii", "hiwin-xeg"])
        self.assertEqual(result.stdout.count("Cstep [A]1.62"), 2, result.stdout)

    def test_nothing_in_the_range_exits_1_without_a_snippet(self):
        self.start_buses()
        result = self.scan("--port", self.path("line"), "--from", 6, "--to", 8)
        self.assertEqual(result.returncode, 1, result.stderr)
        self.assertEqual(result.stdout, "")
        self.assertIn("no device answered at addresses 6-8", result.stderr)
        # The ASCII station outside the range is mentioned, not listed.
        self.assertIn("station 5 answered `$` but is outside the range 6-8", result.stderr)

    def test_a_port_that_cannot_be_opened_exits_2_and_says_why(self):
        missing = self.path("no-such-port")
        result = self.scan("--port", missing)
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertEqual(result.stdout, "")
        self.assertIn(missing, result.stderr)
        self.assertIn("No such file or directory", result.stderr)
        self.assertIn("stop a fieldbridge gateway", result.stderr)

        not_a_tty = self.path("plain-file")
        with open(not_a_tty, "w") as f:
            f.write("x")
        result = self.scan("--port", not_a_tty)
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertIn("not a serial port", result.stderr)

    def test_usage_errors_exit_64(self):
        for args in (["--from", 9, "--to", 3], ["--parity", "X"], ["--to", 255], ["--baud", 1234], []):
            with self.subTest(args=args):
                result = self.scan(*(["--port", self.path("line")] if args else []) + args)
                self.assertEqual(result.returncode, 64, result.stderr)
                self.assertEqual(result.stdout, "")
        result = self.scan("--port", self.path("line"), "--from", 9, "--to", 3)
        self.assertIn("--from 9 is above --to 3", result.stderr)


def main():
    global FIELDBRIDGE
    argv = list(sys.argv)
    if "--fieldbridge" in argv:
        i = argv.index("--fieldbridge")
        FIELDBRIDGE = argv[i + 1]
        del argv[i:i + 2]
    if not FIELDBRIDGE or not os.access(FIELDBRIDGE, os.X_OK):
        sys.exit("give the fieldbridge binary with --fieldbridge PATH")
    sys.argv = argv
    simlib.main()


if __name__ == "__main__":
    main()
