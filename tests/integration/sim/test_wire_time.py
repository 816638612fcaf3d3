"""Wire-time emulation measured from outside: a reply never arrives before a real
line could have delivered it (request + 3.5-character silence + turnaround +
reply), and it arrives within the same order of magnitude of that moment (how close:
the Release benchmark fb_bench_line, docs/performance.md). Also the gap and collision
counters."""

import os
import statistics
import sys
import time

import simlib
from simlib import rtu, transact

# EXCD203MB at address 3: read rabs, 2 registers (manual 002, example at id 1).
READ_RABS = rtu("03 03 02 01 00 02")  # 8 bytes
RABS_REPLY_LEN = 9                     # 03 03 04 xx xx xx xx CRC CRC


def line_time(baud, bits, req, resp, turnaround_s):
    tc = bits / baud
    return req * tc + 3.5 * tc + turnaround_s + resp * tc


class WireTime(simlib.SimTestCase):

    def measure(self, fd, count, pause):
        latencies = []
        for _ in range(count):
            t0 = time.perf_counter()
            reply = transact(fd, READ_RABS, RABS_REPLY_LEN)
            t1 = time.perf_counter()
            self.assertEqual(len(reply), RABS_REPLY_LEN, reply.hex(" "))
            self.assertTrue(simlib.crc_ok(reply))
            latencies.append(t1 - t0)
            time.sleep(pause)  # the master's silence before the next request (under test)
        return latencies

    def test_two_register_read_at_115200(self):
        self.start("--bus", self.path("line-a") + ":excd203mb@3", "--wire-time", "--baud", "115200",
                   "--turnaround", "1ms", "--control", self.path("sim.sock"))
        fd = self.open_port("line-a")
        ideal = line_time(115200, 10, 8, 9, 0.001)
        self.assertAlmostEqual(ideal, 0.002779, places=5)  # spec section 9: 2.78 ms
        latencies = self.measure(fd, 200, 0.001)
        early = [x for x in latencies if x < ideal]
        self.assertEqual(early, [], "replies earlier than the emulated line allows")
        late = sorted(x - ideal for x in latencies)
        median = statistics.median(late)
        p99 = late[int(len(late) * 0.99) - 1]
        stats = self.stats()["buses"]["line-a"]
        timing = stats["timing"]
        sys.stderr.write(
            "\n  wire time at 115200, 1 ms turnaround: ideal %.3f ms; seen by the client "
            "median %.3f ms (+%.0f us), p99 +%.0f us, max +%.0f us; simulator's own write "
            "lateness mean %.1f us, max %.1f us, >100 us: %d of %d\n"
            % (ideal * 1e3, (ideal + median) * 1e3, median * 1e6, p99 * 1e6, late[-1] * 1e6,
               timing["late_us_mean"], timing["late_us_max"], timing["late_over_100us"],
               timing["writes"]))
        # A functional bound, not a performance figure (this runs in the sanitizer
        # build, beside other tests): a simulator that timed the line an order of
        # magnitude slower (9600 for 115200 adds ~20 ms) fails it. The precise figure
        # (median within +2 ms of the ideal) is the Release benchmark's: fb_bench_line,
        # "floor reply time".
        self.assertLess(median, 5 * ideal)
        self.assertEqual(stats["replies"], 200)
        self.assertEqual(timing["writes"], 200)
        self.assertEqual(stats["gap_violations"], 0)  # 1 ms pause > 3.5 characters
        self.assertEqual(stats["collisions"], 0)
        self.assertGreater(stats["busy_ms"], 200 * (8 + 9) * 10 / 115200 * 1e3 * 0.999)

    def test_parity_makes_characters_longer(self):
        # 9600 8E1: 11 bits a character.
        self.start("--bus", self.path("line-a") + ":excd203mb@3", "--wire-time", "--baud", "9600",
                   "--parity", "E", "--turnaround", "2ms")
        fd = self.open_port("line-a")
        ideal = line_time(9600, 11, 8, 9, 0.002)
        for latency in self.measure(fd, 5, 0.01):
            self.assertGreaterEqual(latency, ideal)
            # A functional bound: a reply one more request-and-reply time late (~25 ms)
            # fails it; the longer characters are what the line above checks.
            self.assertLess(latency, ideal + 0.02)

    def test_request_without_silence_is_a_gap_violation(self):
        # 1200 bps: 3.5 characters are 29 ms, far longer than the client's reaction.
        self.start("--bus", self.path("line-a") + ":excd203mb@3", "--baud", "1200",
                   "--control", self.path("sim.sock"))
        fd = self.open_port("line-a")
        self.assertEqual(len(transact(fd, READ_RABS, RABS_REPLY_LEN)), RABS_REPLY_LEN)
        self.assertEqual(len(transact(fd, READ_RABS, RABS_REPLY_LEN)), RABS_REPLY_LEN)
        stats = self.stats()["buses"]["line-a"]
        self.assertEqual(stats["gap_violations"], 1)
        self.assertLess(stats["min_silence_us"], 29166)
        time.sleep(0.06)  # now a proper silence (> 29 ms: the silence is under test)
        self.assertEqual(len(transact(fd, READ_RABS, RABS_REPLY_LEN)), RABS_REPLY_LEN)
        self.assertEqual(self.stats()["buses"]["line-a"]["gap_violations"], 1)
        # Two requests in one write: the second has no silence at all.
        time.sleep(0.06)
        os.write(fd, READ_RABS + READ_RABS)
        self.assertEqual(len(simlib.read_exactly(fd, 2 * RABS_REPLY_LEN)), 2 * RABS_REPLY_LEN)
        stats = self.stats()["buses"]["line-a"]
        self.assertEqual(stats["gap_violations"], 2)
        self.assertEqual(stats["min_silence_us"], 0)
        self.assertEqual(stats["requests"], 5)

    def test_request_while_a_reply_is_pending_collides(self):
        self.start("--bus", self.path("line-a") + ":excd203mb@3", "--wire-time", "--baud", "9600",
                   "--control", self.path("sim.sock"))
        fd = self.open_port("line-a")
        # The reply needs ~22 ms at 9600; the second request arrives long before.
        os.write(fd, READ_RABS)
        time.sleep(0.002)  # the second request inside the first's reply time (under test)
        os.write(fd, READ_RABS)
        data = simlib.read_for(fd, 0.3)
        self.assertEqual(len(data), RABS_REPLY_LEN, "the device answers once: " + data.hex(" "))
        stats = self.stats()["buses"]["line-a"]
        self.assertEqual(stats["collisions"], 1)
        self.assertEqual(stats["collision_bytes"], 8)
        self.assertEqual(stats["requests"], 1)
        # Back to back in one write collides the same way.
        os.write(fd, READ_RABS + READ_RABS)
        data = simlib.read_for(fd, 0.3)
        self.assertEqual(len(data), RABS_REPLY_LEN)
        self.assertEqual(self.stats()["buses"]["line-a"]["collisions"], 2)


if __name__ == "__main__":
    simlib.main()
