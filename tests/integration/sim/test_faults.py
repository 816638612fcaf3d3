"""Fault injection from outside: through the control socket (`fault ...`) and the
--fault option, each kind seen on the pseudo-terminal as a master would see it:
drop (no reply), corrupt-crc (the reply's CRC is wrong), truncate (half the reply),
delay (the reply N ms later), garbage (bytes ahead of the reply), echo (the request
comes back before the reply), dead / revive, unplug (the pty and its link vanish for
a while). Triggers always / next=N / a probability (reproducible with --seed) / off,
`fault clear`, and the counters of `stats` for each."""

import os
import time

import simlib
from simlib import h, read_for, read_line, rtu, transact

NO_REPLY_WAIT = 0.2

READ_RABS = rtu("03 03 02 01 00 02")           # EXCD203MB at 3
RABS_REPLY = rtu("03 03 04 00 00 00 00")
READ_STATUS = h("02 04 03 01 00 01 60 7D")     # XEG at 2 (manual, Appendix 1)
STATUS_IDLE = h("02 04 02 00 00 FD 30")
ASCII_G = simlib.ascii_frame(">05g")           # WTEC ASCII at 5
ASCII_G_REPLY = simlib.ascii_frame(">05g00")

LINE = ":hiwin-xeg@2,excd203mb@3,wtec-ascii@5"


class Faults(simlib.SimTestCase):

    def start_line(self, *extra):
        self.start("--bus", self.path("line-a") + LINE, "--control", self.path("sim.sock"),
                   "--seed", "1", *extra)
        return self.open_port("line-a")

    def ok(self, line):
        self.assertEqual(self.control(line), "ok", line)

    def device(self, address):
        return self.stats()["buses"]["line-a"]["devices"][str(address)]

    def answered_normally(self, fd):
        self.assertEqual(transact(fd, READ_RABS, len(RABS_REPLY)), RABS_REPLY)
        self.assertEqual(transact(fd, READ_STATUS, len(STATUS_IDLE)), STATUS_IDLE)
        os.write(fd, ASCII_G)
        self.assertEqual(read_line(fd), ASCII_G_REPLY)
        self.assertEqual(read_for(fd, 0.02), b"")

    def test_reply_faults_from_the_control_socket(self):
        fd = self.start_line()
        self.answered_normally(fd)

        # drop: the EXCD at 3 stays silent, the XEG at 2 still answers.
        self.ok("fault line-a@3:drop")
        os.write(fd, READ_RABS)
        self.assertEqual(read_for(fd, NO_REPLY_WAIT), b"")
        self.assertEqual(transact(fd, READ_STATUS, 7), STATUS_IDLE)
        self.assertEqual(self.device(3)["dropped"], 1)
        self.ok("fault line-a@3:drop:off")
        self.assertEqual(transact(fd, READ_RABS, 9), RABS_REPLY)

        # corrupt-crc: same length, same data, CRC wrong (RTU and ASCII).
        self.ok("fault line-a:corrupt-crc")
        reply = transact(fd, READ_RABS, 9)
        self.assertEqual(len(reply), 9)
        self.assertEqual(reply[:-2], RABS_REPLY[:-2])
        self.assertFalse(simlib.crc_ok(reply), reply.hex(" "))
        os.write(fd, ASCII_G)
        line = read_line(fd)
        self.assertEqual(len(line), len(ASCII_G_REPLY))
        self.assertEqual(line[:6], ASCII_G_REPLY[:6])
        self.assertNotEqual(line, ASCII_G_REPLY)
        self.assertEqual(self.device(3)["corrupted"], 1)
        self.assertEqual(self.device(5)["corrupted"], 1)

        # clear (one device, then all): the XEG at 2 still gets a bad CRC after
        # clearing device 3 only, since the rule is bus-wide.
        self.ok("fault clear line-a@3")
        self.assertFalse(simlib.crc_ok(transact(fd, READ_STATUS, 7)))
        self.ok("fault clear")
        self.answered_normally(fd)

        # truncate: the first half of the reply, nothing more.
        self.ok("fault line-a@3:truncate")
        os.write(fd, READ_RABS)
        self.assertEqual(read_for(fd, NO_REPLY_WAIT), RABS_REPLY[:4])
        self.assertEqual(self.device(3)["truncated"], 1)
        self.ok("fault clear line-a@3")

        # delay: the reply comes N ms later than it would.
        self.ok("fault line-a@3:delay:150")
        t0 = time.monotonic()
        os.write(fd, READ_RABS)
        self.assertEqual(read_for(fd, 0.1), b"", "nothing within 100 ms")
        self.assertEqual(simlib.read_exactly(fd, 9, timeout=2.0), RABS_REPLY)
        self.assertGreaterEqual(time.monotonic() - t0, 0.15)
        self.assertEqual(self.device(3)["delayed"], 1)
        stats = self.stats()["buses"]["line-a"]
        self.assertEqual(stats["faults"], [{"kind": "delay", "device": 3, "ms": 150.0, "when": "always"}])
        self.ok("fault clear")

        # garbage: 1-8 bytes ahead of an intact reply (never '>', so ASCII still frames).
        self.ok("fault line-a:garbage")
        for request, expected in ((READ_RABS, RABS_REPLY), (ASCII_G, ASCII_G_REPLY)):
            os.write(fd, request)
            data = read_for(fd, NO_REPLY_WAIT)
            self.assertTrue(data.endswith(expected), data)
            noise = data[:-len(expected)]
            self.assertTrue(1 <= len(noise) <= 8, data)
            self.assertNotIn(b">", noise)
        self.assertEqual(self.device(3)["garbage_injected"], 1)
        self.assertEqual(self.device(5)["garbage_injected"], 1)
        self.ok("fault clear")

        # echo (bus-wide, like a 2-wire adapter): the request, then the reply.
        self.ok("fault line-a:echo")
        self.assertEqual(transact(fd, READ_RABS, 8 + 9), READ_RABS + RABS_REPLY)
        os.write(fd, rtu("09 03 02 01 00 02"))  # nobody at 9: only the echo comes back
        self.assertEqual(read_for(fd, NO_REPLY_WAIT), rtu("09 03 02 01 00 02"))
        os.write(fd, ASCII_G)
        self.assertEqual(read_line(fd), ASCII_G)
        self.assertEqual(read_line(fd), ASCII_G_REPLY)
        self.assertEqual(self.stats()["buses"]["line-a"]["echoes"], 3)
        self.ok("fault clear")

        # dead / revive: the device ignores everything until revived.
        self.ok("fault line-a@2:dead")
        os.write(fd, READ_STATUS)
        self.assertEqual(read_for(fd, NO_REPLY_WAIT), b"")
        self.assertEqual(self.device(2)["ignored_dead"], 1)
        self.assertTrue(self.device(2)["dead"])
        self.ok("fault line-a@2:revive")
        self.answered_normally(fd)

        stats = self.stats()["buses"]["line-a"]
        self.assertEqual(stats["faults"], [])
        self.assertEqual(stats["dropped"], 1)
        self.assertEqual(stats["crc_errors"], 0)  # faults hit replies, never the requests

    def test_fault_specs_that_are_wrong_are_refused(self):
        self.start_line()
        for spec, words in (("fault line-a@3:melt", "unknown fault kind"),
                            ("fault line-x@3:drop", "no bus named"),
                            ("fault line-a@9:drop", "no device at address 9"),
                            ("fault line-a@3:delay", "needs a duration"),
                            ("fault line-a@3:drop:2.5", "is not a trigger"),
                            ("fault line-a@3:echo", "bus-wide")):
            reply = self.control(spec)
            self.assertTrue(reply.startswith("error: ") and words in reply, "%s -> %s" % (spec, reply))
        self.assertEqual(self.stats()["buses"]["line-a"]["faults"], [])

    def status_answered(self, fd):
        """Asks the XEG for its status, then the EXCD for rabs: the EXCD's reply marks
        the end, so a missing XEG reply is known without waiting for a timeout."""
        os.write(fd, READ_STATUS)
        os.write(fd, READ_RABS)
        data = b""
        deadline = time.monotonic() + 2.0
        while not data.endswith(RABS_REPLY) and time.monotonic() < deadline:
            data += read_for(fd, 0.005)
        self.assertTrue(data.endswith(RABS_REPLY), data.hex(" "))
        self.assertIn(data[:-len(RABS_REPLY)], (b"", STATUS_IDLE))
        return data == STATUS_IDLE + RABS_REPLY

    def test_command_line_faults_next_n_and_probability(self):
        fd = self.start_line("--fault", "line-a@3:drop:next=2", "--fault", "line-a@2:drop:0.5")
        self.assertEqual(self.stats()["buses"]["line-a"]["faults"][0]["when"], "next=2")
        for _ in range(2):
            os.write(fd, READ_RABS)
            self.assertEqual(read_for(fd, 0.1), b"")
        self.assertEqual(transact(fd, READ_RABS, 9), RABS_REPLY)
        # Probability 0.5 with --seed 1: some replies missing, some not, and the counter
        # says how many.
        pattern = [self.status_answered(fd) for _ in range(30)]
        dropped = pattern.count(False)
        self.assertTrue(5 <= dropped <= 25, pattern)
        stats = self.stats()["buses"]["line-a"]
        self.assertEqual(stats["devices"]["2"]["dropped"], dropped)
        self.assertEqual(stats["devices"]["3"]["dropped"], 2)
        self.assertEqual([f["kind"] for f in stats["faults"]], ["drop"])  # next=2 is used up
        self.sims[-1].kill()

        # The same seed and the same traffic drop the same replies.
        os.close(self.fds.pop())
        fd = self.start_line("--fault", "line-a@3:drop:next=2", "--fault", "line-a@2:drop:0.5")
        for _ in range(2):
            os.write(fd, READ_RABS)
            read_for(fd, 0.1)
        self.assertEqual(transact(fd, READ_RABS, 9), RABS_REPLY)
        again = [self.status_answered(fd) for _ in range(30)]
        self.assertEqual(again, pattern)

    def test_unplug_removes_the_pty_for_a_while(self):
        fd = self.start_line()
        link = self.path("line-a")
        self.ok("fault line-a:unplug:800")
        self.assertFalse(os.path.lexists(link), "the link is gone while unplugged")
        self.assertTrue(self.control("fault line-a:unplug:800").startswith("error: "))
        os.close(self.fds.pop())
        self.assertTrue(simlib.wait_until(lambda: os.path.exists(link), 5.0), "the link came back")
        fd = self.open_port("line-a")
        self.answered_normally(fd)
        self.assertEqual(self.stats()["buses"]["line-a"]["unplugs"], 1)


if __name__ == "__main__":
    simlib.main()
