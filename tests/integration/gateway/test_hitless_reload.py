"""SIGHUP applies only the difference (spec section 7, docs/service.md "Reload"): while a
client reads a line without pause, reloads that change only another line, or only a
device's max_age / command_ttl, fail no request, reopen no port (the simulator counts the
gateway's opens of each pty with inotify) and leave no gap on the client's reads beyond
what one transaction costs. The line that did change restarts, and the count shows it.
MQTT stays connected through reloads that leave its settings alone."""

import signal
import threading
import time
import unittest

import gatewaylib as gl
import simlib

XEG_POSITION = 0x0300
READ_UNIT = 5  # gripper-4 on line-b, max_age 0: every read goes to the line
# One 2-register XEG read at 115200 8N1 with the simulator's 1 ms turnaround: (8 + 9)
# bytes x 86.8 us + 2 x 304 us of silence + 1 ms = 3.08 ms (spec section 9).
TRANSACTION_S = 0.00308
# The client's own share of a gap (Python, pymodbus, a 2-core machine shared with the
# sanitizer-built gateway and simulator): what a gap may exceed the baseline's worst by
# besides the one transaction. Measured on the CI machine: docs/service.md "Reload".
CLIENT_JITTER_S = 0.010


class Reader(threading.Thread):
    """Reads unit 5 back to back on its own connection; records (time done, ok)."""

    def __init__(self, case):
        super().__init__(daemon=True)
        self.client = case.client()
        self.results = []
        self.stop = threading.Event()
        self.failures = []

    def run(self):
        deadline = time.monotonic() + 60  # bounded whatever happens
        while not self.stop.is_set() and time.monotonic() < deadline:
            try:
                reply = self.client.read_input_registers(XEG_POSITION, 2, slave=READ_UNIT)
                ok = not reply.isError()
                if not ok:
                    self.failures.append(repr(reply))
            except Exception as error:  # pylint: disable=broad-except
                ok = False
                self.failures.append(repr(error))
            self.results.append((time.monotonic(), ok))

    def gaps(self, start, end):
        """Intervals between consecutive completions that end within [start, end]."""
        times = [t for t, _ in self.results]
        return [b - a for a, b in zip(times, times[1:]) if start <= b <= end]


class HitlessReload(gl.CellTestCase):

    def bus(self, name):
        return self.sim_stats()["buses"][name]

    def rewrite(self, old, new):
        with open(self.config_path, encoding="utf-8") as f:
            text = f.read()
        self.assertIn(old, text)
        with open(self.config_path, "w", encoding="utf-8") as f:
            f.write(text.replace(old, new, 1))

    def reload(self, expect):
        """SIGHUP; returns (sent, done) once the log says `expect` and the reload is applied."""
        mark = len(self.gateway.text().splitlines())
        sent = time.monotonic()
        self.gateway.signal(signal.SIGHUP)
        if self.gateway.wait_line(lambda line: expect in line, gl.IO_TIMEOUT, start=mark) is None:
            self.fail("no %r after SIGHUP:\n%s" % (expect, self.gateway.text()))
        if self.gateway.wait_line(lambda line: "configuration reloaded" in line, gl.IO_TIMEOUT,
                                  start=mark) is None:
            self.fail("reload not applied:\n%s" % self.gateway.text())
        return sent, time.monotonic()

    def more_reads(self, reader, count):
        target = len(reader.results) + count
        self.assertTrue(simlib.wait_until(lambda: len(reader.results) >= target, gl.IO_TIMEOUT, interval=0.01),
                        "the reader stalled at %d reads" % len(reader.results))

    def test_reloads_leave_unchanged_lines_and_devices_running(self):
        self.start_cell(mqtt=True, sim_line_b="wtec-rtu@1,hiwin-xeg@2",
                        extra_devices_b="      - {name: gripper-4, type: hiwin-xeg, address: 2, unit_id: 5, "
                                        "max_age: 0ms, command_ttl: 2s}\n")
        self.assertTrue(simlib.wait_until(lambda: self.bus("line-b")["port_opens"] == 1
                                          and self.bus("line-a")["port_opens"] == 1, gl.IO_TIMEOUT),
                        self.sim_stats())
        connects = self.gateway.text().count("MQTT: broker")

        reader = Reader(self)
        reader.start()
        self.more_reads(reader, 20)  # the reader's connection is warm
        base_start = time.monotonic()
        self.more_reads(reader, 300)
        base_end = time.monotonic()

        windows = []
        # 1. Another line changes (line-a's response timeout): line-a restarts, line-b not.
        self.rewrite("    response_timeout: 300ms\n    broadcast_unit: 100\n",
                     "    response_timeout: 250ms\n    broadcast_unit: 100\n")
        windows.append(self.reload("lines restarted: line-a"))
        self.more_reads(reader, 100)
        # 2. Another device of the read line changes its max_age: retuned in place.
        self.rewrite("{name: gripper-3, type: wtec-rtu, address: 1, unit_id: 4, command_ttl: 2s}",
                     "{name: gripper-3, type: wtec-rtu, address: 1, unit_id: 4, command_ttl: 2s, max_age: 1s}")
        windows.append(self.reload("devices retuned: gripper-3"))
        self.more_reads(reader, 100)
        # 3. The device being read changes its own command_ttl and max_age (still 0).
        self.rewrite("max_age: 0ms, command_ttl: 2s}", "max_age: 0s, command_ttl: 3s}")
        windows.append(self.reload("devices retuned: gripper-4"))
        self.more_reads(reader, 100)
        reader.stop.set()
        reader.join(gl.IO_TIMEOUT)

        self.assertEqual(reader.failures, [], "requests failed during the reloads")
        line_b = self.bus("line-b")
        self.assertEqual((line_b["port_opens"], line_b["port_closes"]), (1, 0),
                         "line-b's port was reopened: %s" % line_b)
        self.assertEqual(self.bus("line-a")["port_opens"], 2, "line-a should have restarted once")
        self.assertEqual(self.gateway.text().count("MQTT: broker"), connects, "MQTT reconnected")
        self.assertNotIn("MQTT: configuration changed", self.gateway.text())

        baseline = reader.gaps(base_start, base_end)
        self.assertGreater(len(baseline), 100)
        worst_baseline = max(baseline)
        for n, (sent, done) in enumerate(windows, 1):
            gaps = reader.gaps(sent, done + 0.05)
            self.assertTrue(gaps, "no read completed during reload %d" % n)
            worst = max(gaps)
            print("reload %d: %d reads, worst gap %.1f ms (baseline worst %.1f ms, median %.1f ms)"
                  % (n, len(gaps), worst * 1e3, worst_baseline * 1e3, sorted(baseline)[len(baseline) // 2] * 1e3))
            self.assertLessEqual(worst, worst_baseline + TRANSACTION_S + CLIENT_JITTER_S,
                                 "reload %d held the line up longer than one transaction" % n)


if __name__ == "__main__":
    gl.main()
