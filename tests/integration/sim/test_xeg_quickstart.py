"""HIWIN XEG-C2 quick start (manual 001, Appendix 1) replayed byte for byte over the
simulator's pseudo-terminal, with and without wire-time emulation. The manual's
"wait 30 s / 3 s" steps are replaced by polling the status until it changes
(bounded), so the test takes as long as the model's motion does."""

import os

import simlib
from simlib import h, read_for, transact

# Appendix 1, scenario numbers in the comments.
WRITE_MODEL = h("02 10 06 00 00 01 02 0A 20 D3 D8")          # 1
WRITE_MODEL_REPLY = h("02 10 06 00 00 01 01 72")               # 2
READ_MODEL = h("02 03 06 00 00 01 84 B1")                      # 3
READ_MODEL_REPLY = h("02 03 02 0A 20 FB 3C")                   # 4
READ_FIRMWARE = h("02 04 03 03 00 04 01 BE")                   # 5
READ_FIRMWARE_REPLY = h("02 04 08 00 03 00 00 00 01 03 74 49 5E")  # 6: V3.0.1.884
WRITE_RESET = h("02 10 06 10 00 01 02 00 01 17 F0")            # 7
WRITE_RESET_REPLY = h("02 10 06 10 00 01 00 B7")               # 8
READ_STATUS = h("02 04 03 01 00 01 60 7D")                     # 9, 12, 16, 19, 23, 26
STATUS_WORKING = h("02 04 02 00 01 3C F0")                     # 10, 17, 24
STATUS_IDLE = h("02 04 02 00 00 FD 30")                        # 13, 20
STATUS_POSITIONED = h("02 04 02 00 02 7C F1")                  # 27
WRITE_EXPERT = h("02 10 06 40 00 07 0E 00 00 03 E8 1F 40 01 F4 07 D0 00 64 00 01 E6 B8")  # 14
WRITE_EXPERT_REPLY = h("02 10 06 40 00 07 80 A4")              # 15
BROADCAST_MOVE = h("00 10 06 30 00 03 06 0C 80 1F 40 00 01 3C A4")  # 21, no reply (22)

MOTION_TIMEOUT = 60.0  # the manual waits 30 s after reset; the model may be faster


class XegQuickStart(simlib.SimTestCase):

    def read_position(self, fd):
        """Input register 0x0300, 0.01 mm (manual 001, section 3)."""
        reply = transact(fd, simlib.rtu("02 04 03 00 00 01"), 7)
        self.assertTrue(simlib.crc_ok(reply), reply.hex(" "))
        return reply[3] << 8 | reply[4]

    def wait_status(self, fd, expected):
        last = []

        def poll():
            reply = transact(fd, READ_STATUS, len(expected))
            last[:] = [reply]
            return reply == expected
        ok = simlib.wait_until(poll, MOTION_TIMEOUT, interval=0.05)
        self.assertTrue(ok, "status never became %s; last reply %s"
                        % (expected.hex(" "), last[0].hex(" ") if last else None))

    def replay(self, *extra):
        self.start("--bus", self.path("line-a") + ":hiwin-xeg@2", "--control", self.path("sim.sock"),
                   *extra)
        fd = self.open_port("line-a")
        self.assertEqual(transact(fd, WRITE_MODEL, 8), WRITE_MODEL_REPLY)
        self.assertEqual(transact(fd, READ_MODEL, 7), READ_MODEL_REPLY)
        self.assertEqual(transact(fd, READ_FIRMWARE, 13), READ_FIRMWARE_REPLY)
        self.assertEqual(transact(fd, WRITE_RESET, 8), WRITE_RESET_REPLY)
        self.assertEqual(transact(fd, READ_STATUS, 7), STATUS_WORKING)
        self.wait_status(fd, STATUS_IDLE)
        self.assertEqual(self.read_position(fd), 3200)  # "Idle, 32.00 mm"
        self.assertEqual(transact(fd, WRITE_EXPERT, 8), WRITE_EXPERT_REPLY)
        self.assertEqual(transact(fd, READ_STATUS, 7), STATUS_WORKING)
        self.wait_status(fd, STATUS_IDLE)
        self.assertEqual(self.read_position(fd), 1700)  # "Idle, 17.00 mm"
        # The move takes about 0.2 s: read the status at once. Nobody answers the
        # broadcast, so the first bytes back are the status reply and nothing else.
        os.write(fd, BROADCAST_MOVE)
        self.assertEqual(transact(fd, READ_STATUS, 7), STATUS_WORKING)
        self.assertEqual(read_for(fd, 0.05), b"", "nobody answers a broadcast")
        self.wait_status(fd, STATUS_POSITIONED)
        self.assertEqual(self.read_position(fd), 3200)  # "positioned, 32.00 mm"
        stats = self.stats()["buses"]["line-a"]
        self.assertEqual(stats["broadcasts"], 1)
        self.assertEqual(stats["crc_errors"], 0)
        self.assertEqual(stats["garbage_bytes"], 0)
        self.assertEqual(stats["devices"]["2"]["type"], "hiwin-xeg")
        self.assertGreaterEqual(stats["devices"]["2"]["replies"], 12)
        return stats

    def test_quick_start_instant(self):
        self.replay()

    def test_quick_start_with_wire_time(self):
        stats = self.replay("--wire-time", "--baud", "115200", "--turnaround", "1ms")
        self.assertTrue(stats["wire_time"])
        self.assertGreater(stats["busy_ms"], 0)
        self.assertEqual(stats["timing"]["writes"], stats["replies"])


if __name__ == "__main__":
    simlib.main()
