"""SIGHUP applies only the difference (spec section 7, docs/service.md "Reload"): while a
client reads a line without pause, reloads that change only another line, or only a
device's max_age / command_ttl, fail no request, reopen no port (the simulator counts the
gateway's opens of each pty with inotify) and leave the line idle no longer than one
transaction (the simulator measures the idle time between frames on the emulated wire). The line that did change restarts, and the count shows it.
Each kind of reload runs five times and is judged by its median round, so that a stall
of a shared machine does not pass for a cost of the reload.
MQTT stays connected through reloads that leave its settings alone."""

import collections
import json
import os
import re
import signal
import statistics
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
# The packaged (Release) binaries, as tests/package/test-package.sh runs this test on
# what it installed: there the spec's bound holds for every reload, "no gap longer
# than one transaction". The sanitizer build of ctest is several times slower at a
# line restart and is held to looser bounds (below).
RELEASE_BUILD = os.environ.get("FIELDBRIDGE_RELEASE_BUILD") == "1"
# Each kind of reload, done and undone in turn. The first round of the first kind is
# cold (the first reload of a process reads and builds what later ones find warm: CI saw
# 59 ms held against 4 ms in later rounds), so with three rounds the median was the
# worse of two; with five, one stall of the machine and the cold round both fall outside it.
ROUNDS = 5
# One reload: when SIGHUP was sent and the apply seen, line-b's silence window around it,
# and the wall time and CPU time the apply held the loop (from its log line), in seconds.
Round = collections.namedtuple("Round", "sent done silence held_s cpu_s")


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
                reply = self.client.read_input_registers(XEG_POSITION, count=2, slave=READ_UNIT)
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

    def silence_window(self):
        """Requests and the longest idle time of line-b since the previous call (the
        simulator measures it on the emulated wire: end of a frame to the next request)."""
        return json.loads(self.control("silence line-b")[3:])

    def reload(self, expect):
        """SIGHUP; once the log says `expect` and the reload is applied, its Round."""
        self.silence_window()
        mark = len(self.gateway.text().splitlines())
        sent = time.monotonic()
        self.gateway.signal(signal.SIGHUP)
        if self.gateway.wait_line(lambda line: expect in line, gl.IO_TIMEOUT, start=mark) is None:
            self.fail("no %r after SIGHUP:\n%s" % (expect, self.gateway.text()))
        applied = self.gateway.wait_line(lambda line: "configuration reloaded" in line, gl.IO_TIMEOUT,
                                         start=mark)
        if applied is None:
            self.fail("reload not applied:\n%s" % self.gateway.text())
        print(applied[1][applied[1].find("; read and checked") + 2:])
        held = re.search(r"applied in ([0-9.]+) ms on the loop, ([0-9.]+) ms of CPU", applied[1])
        self.assertIsNotNone(held, applied[1])
        done = time.monotonic()
        self.more_reads(self.readers, 30)  # the line carried on after the reload
        return Round(sent, done, self.silence_window(), float(held.group(1)) / 1e3, float(held.group(2)) / 1e3)

    def more_reads(self, readers, count):
        def total():
            return sum(len(reader.results) for reader in readers)
        target = total() + count
        self.assertTrue(simlib.wait_until(lambda: total() >= target, gl.IO_TIMEOUT, interval=0.01),
                        "the readers stalled at %d reads" % total())

    def test_reloads_leave_unchanged_lines_and_devices_running(self):
        self.start_cell(mqtt=True, sim_line_b="wtec-rtu@1,hiwin-xeg@2",
                        extra_devices_b="      - {name: gripper-4, type: hiwin-xeg, address: 2, unit_id: 5, "
                                        "max_age: 0ms, command_ttl: 2s}\n")
        self.assertTrue(simlib.wait_until(lambda: self.bus("line-b")["port_opens"] == 1
                                          and self.bus("line-a")["port_opens"] == 1, gl.IO_TIMEOUT),
                        self.sim_stats())
        connects = self.gateway.text().count("MQTT: broker")

        # Three clients keep line-b's queue from running dry, so the line's idle time is
        # the gateway's, not the time a client takes to send its next request.
        self.readers = [Reader(self) for _ in range(3)]
        for reader in self.readers:
            reader.start()
        self.more_reads(self.readers, 30)  # the connections are warm
        self.silence_window()
        self.more_reads(self.readers, 600)
        base_silence = self.silence_window()

        # Each kind of reload runs ROUNDS times, its change made and then undone, and is
        # judged by the median of its rounds: a cost the code adds shows in every round,
        # while a stall of this shared machine (the baseline window above idles the line
        # up to 11 ms without any reload) lands in one round, not in most of them.
        kinds = [
            # 1. Another line changes (line-a's response timeout): line-a restarts, line-b not.
            ("lines restarted: line-a",
             "    response_timeout: 300ms\n    broadcast_unit: 100\n",
             "    response_timeout: 250ms\n    broadcast_unit: 100\n"),
            # 2. Another device of the read line changes its max_age: retuned in place.
            ("devices retuned: gripper-3",
             "{name: gripper-3, type: wtec-rtu, address: 1, unit_id: 4, command_ttl: 2s}",
             "{name: gripper-3, type: wtec-rtu, address: 1, unit_id: 4, command_ttl: 2s, max_age: 1s}"),
            # 3. The device being read changes its own command_ttl (its max_age stays 0).
            ("devices retuned: gripper-4", "max_age: 0ms, command_ttl: 2s}", "max_age: 0ms, command_ttl: 3s}"),
        ]
        # Per kind, its Rounds.
        rounds = {expect: [] for expect, _, _ in kinds}
        for round_number in range(ROUNDS):
            for expect, before, after in kinds:
                old, new = (before, after) if round_number % 2 == 0 else (after, before)
                self.rewrite_config(old, new)
                rounds[expect].append(self.reload(expect))
                self.more_reads(self.readers, 30)
        for reader in self.readers:
            reader.stop.set()
        for reader in self.readers:
            reader.join(gl.IO_TIMEOUT)

        for reader in self.readers:
            self.assertEqual(reader.failures, [], "requests failed during the reloads")
        line_b = self.bus("line-b")
        self.assertEqual((line_b["port_opens"], line_b["port_closes"]), (1, 0),
                         "line-b's port was reopened: %s" % line_b)
        self.assertEqual(self.bus("line-a")["port_opens"], 1 + ROUNDS,
                         "line-a should have restarted once a round")
        self.assertEqual(self.gateway.text().count("MQTT: broker"), connects, "MQTT reconnected")
        self.assertNotIn("MQTT: configuration changed", self.gateway.text())

        print("baseline: %d requests on line-b, longest idle %.0f us" % (base_silence["requests"],
                                                                       base_silence["max_silence_us"]))
        self.assertGreater(base_silence["requests"], 300)
        for n, (expect, _, _) in enumerate(kinds, 1):
            for one in rounds[expect]:
                gaps = [gap for reader in self.readers for gap in reader.gaps(one.sent, one.done + 0.05)]
                self.assertTrue(gaps, "no read completed during a reload of kind %d (%s)" % (n, expect))
                print("reload %d (%s): %d requests on line-b, longest idle %.0f us; longest client gap "
                      "%.1f ms; loop held %.2f ms, %.2f ms of CPU"
                      % (n, expect, one.silence["requests"], one.silence["max_silence_us"], max(gaps) * 1e3,
                         one.held_s * 1e3, one.cpu_s * 1e3))
            idle_us = statistics.median(one.silence["max_silence_us"] for one in rounds[expect])
            median_held = statistics.median(one.held_s for one in rounds[expect])
            median_cpu = statistics.median(one.cpu_s for one in rounds[expect])
            # The loop drives every line: what a reload's apply holds it for is the most it
            # can add to a line's idle time. A retune costs well under a transaction; a
            # reload that restarts another line (close, build, open) about one in this
            # sanitizer build, a quarter of that in Release. That cost is the loop thread's
            # CPU time; the wall time adds whatever else the OS ran on that core meanwhile
            # (the simulator, three Python clients, the sanitizer's threads: CI once saw a
            # restart whose components took 4.9 ms hold the loop 8.8 ms). So the CPU time
            # is held to the aim and the wall time to a stall bound.
            limit = TRANSACTION_S if n > 1 or RELEASE_BUILD else 2 * TRANSACTION_S
            self.assertLessEqual(median_cpu, limit, "reload %d: the median round cost the loop %.2f ms "
                                 "of CPU" % (n, median_cpu * 1e3))
            stall = (2 if RELEASE_BUILD else 5) * TRANSACTION_S
            self.assertLessEqual(median_held, stall, "reload %d: the median round held the loop %.2f ms"
                                 % (n, median_held * 1e3))
            # The line's own idle time, measured on the wire, against the same run's
            # baseline: the spec's aim of one transaction in Release; this sanitizer build
            # is held to three (a reopened or rebuilt line idles it for tens of ms).
            self.assertLessEqual(idle_us, base_silence["max_silence_us"]
                                 + (1 if RELEASE_BUILD else 3) * TRANSACTION_S * 1e6,
                                 "reload %d: in the median round line-b idled %.0f us, much longer than "
                                 "without a reload" % (n, idle_us))

if __name__ == "__main__":
    gl.main()
