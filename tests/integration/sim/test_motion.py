"""Motion over real time, seen from outside through the pseudo-terminal: homing, a
move at the commanded speed, gripping an object at a set width (hold / gripped), and
alarms injected through the control socket showing in the status and alarm registers.

Speed is checked without a timing tolerance: every position read is bracketed by the
client's clock readings before the command was sent and after the read's reply came
back, and the position must lie on the commanded speed line inside that bracket
(+-1 unit of rounding). A slow machine widens the bracket; it cannot make the check
fail, while a simulator moving at the wrong speed, or jumping, falls outside it."""

import os
import time

import simlib
from simlib import read_for, rtu, transact

MOTION_TIMEOUT = 15.0


class Sample:
    def __init__(self, t_start, t_end, position, status):
        self.t_start, self.t_end, self.position, self.status = t_start, t_end, position, status


class Motion(simlib.SimTestCase):

    # ---- helpers ---------------------------------------------------------------------

    def fc10(self, fd, address, register, values):
        body = "%02X10%04X%04X%02X" % (address, register, len(values), 2 * len(values))
        body += "".join("%04X" % v for v in values)
        reply = transact(fd, rtu(body), 8)
        self.assertEqual(reply, rtu("%02X10%04X%04X" % (address, register, len(values))),
                         "FC10 to 0x%04X: %s" % (register, reply.hex(" ")))

    def fc10_exception(self, fd, address, register, values):
        body = "%02X10%04X%04X%02X" % (address, register, len(values), 2 * len(values))
        body += "".join("%04X" % v for v in values)
        reply = transact(fd, rtu(body), 5)
        self.assertTrue(simlib.crc_ok(reply) and reply[1] == 0x90, reply.hex(" "))
        return reply[2]

    def read_regs(self, fd, address, fc, register, count):
        reply = transact(fd, rtu("%02X%02X%04X%04X" % (address, fc, register, count)), 5 + 2 * count)
        self.assertTrue(simlib.crc_ok(reply) and reply[:3] == bytes([address, fc, 2 * count]),
                        reply.hex(" "))
        return [reply[3 + 2 * i] << 8 | reply[4 + 2 * i] for i in range(count)]

    def follow(self, poll, done):
        """Polls until done(sample); every sample timestamped (bounded)."""
        samples = []
        deadline = time.monotonic() + MOTION_TIMEOUT
        while time.monotonic() < deadline:
            t_start = time.monotonic()
            position, status = poll()
            samples.append(Sample(t_start, time.monotonic(), position, status))
            if done(samples[-1]):
                return samples
            time.sleep(0.02)
        self.fail("motion did not end within %.0f s; last sample position %s status %s"
                  % (MOTION_TIMEOUT, samples[-1].position, samples[-1].status))

    def check_speed_line(self, samples, start, target, speed, t_sent, t_acked, what):
        """Each sample's position lies where a move from @p start to @p target at
        @p speed units/s, begun between t_sent and t_acked, can be while the sample
        was taken. Returns the move time."""
        direction = 1 if target >= start else -1
        travel = abs(target - start)

        def at(elapsed):
            return start + direction * min(max(elapsed, 0.0) * speed, travel)
        for s in samples:
            early, late = at(s.t_start - t_acked), at(s.t_end - t_sent)
            low, high = min(early, late) - 1, max(early, late) + 1
            self.assertTrue(low <= s.position <= high,
                            "%s: position %d at %.3f-%.3f s after the command, the commanded "
                            "speed puts it in %.0f..%.0f"
                            % (what, s.position, s.t_start - t_sent, s.t_end - t_sent, low, high))
        duration = travel / speed
        for s in samples:
            if s.t_end - t_sent < duration - 0.002:
                self.assertNotEqual(s.position, target, what + ": arrived before its time")
        return duration

    # ---- HIWIN XEG-C2 ----------------------------------------------------------------

    def xeg_state(self, fd):
        return tuple(self.read_regs(fd, 2, 0x04, 0x0300, 2))  # position 0.01 mm, status

    def xeg_outputs(self, fd):
        reply = transact(fd, rtu("02 02 00 10 00 08"), 6)
        self.assertTrue(simlib.crc_ok(reply), reply.hex(" "))
        return reply[3]

    def test_xeg_homing_move_hold_and_alarm(self):
        self.start("--bus", self.path("line-a") + ":hiwin-xeg@2,excd203mb@3,wtec-ascii@5",
                   "--control", self.path("sim.sock"))
        fd = self.open_port("line-a")
        self.assertEqual(self.xeg_state(fd), (0, 0))  # powered up closed, idle
        # Move before a reset: refused (04), FC07 says move null (0x07).
        self.assertEqual(self.fc10_exception(fd, 2, 0x0630, [1200, 2000, 1]), 0x04)
        self.assertEqual(transact(fd, rtu("02 07"), 5), rtu("02 07 07"))

        # Reset: homes to the open end, 32.00 mm, at 10.00 mm/s.
        t_sent = time.monotonic()
        self.fc10(fd, 2, 0x0610, [1])
        t_acked = time.monotonic()
        samples = self.follow(lambda: self.xeg_state(fd), lambda s: s.status != 1)
        self.assertEqual((samples[-1].position, samples[-1].status), (3200, 0))
        self.check_speed_line(samples, 0, 3200, 1000, t_sent, t_acked, "homing")

        # Move to 12.00 mm at 20.00 mm/s: 1 s, ends positioned (2), DO POS.
        t_sent = time.monotonic()
        self.fc10(fd, 2, 0x0630, [1200, 2000, 1])
        t_acked = time.monotonic()
        samples = self.follow(lambda: self.xeg_state(fd), lambda s: s.status != 1)
        self.assertEqual((samples[-1].position, samples[-1].status), (1200, 2))
        self.assertGreaterEqual(len(samples), 5, "the move was followed while it ran")
        self.check_speed_line(samples, 3200, 1200, 2000, t_sent, t_acked, "move")
        self.assertEqual(self.xeg_outputs(fd), 0x01)  # POS

        # Back open, then an object 20.00 mm wide: the manual's Expert command (close
        # 10 mm at 80 mm/s, then hold 5 mm at 20 mm/s) meets it and holds it.
        self.fc10(fd, 2, 0x0630, [3200, 8000, 1])
        samples = self.follow(lambda: self.xeg_state(fd), lambda s: s.status != 1)
        self.assertEqual((samples[-1].position, samples[-1].status), (3200, 2))
        self.assertEqual(self.control("device 2 object 20.00"), "ok")
        self.assertEqual(transact(fd, simlib.h("02 10 06 40 00 07 0E 00 00 03 E8 1F 40 01 F4 07 D0 00 "
                                               "64 00 01 E6 B8"), 8), simlib.h("02 10 06 40 00 07 80 A4"))
        samples = self.follow(lambda: self.xeg_state(fd), lambda s: s.status != 1)
        self.assertEqual((samples[-1].position, samples[-1].status), (2000, 3))  # Hold
        self.assertEqual(self.xeg_outputs(fd), 0x02)  # HOLD

        # Injected alarms: status register, DO ALM1/ALM2, FC07 code, motion refused.
        for alarm, fc07, do in ((4, 0x11, 0x08), (5, 0x10, 0x08), (6, 0x12, 0x08), (7, 0x02, 0x10)):
            self.assertEqual(self.control("device 2 alarm %d" % alarm), "ok")
            self.assertEqual(self.xeg_state(fd), (2000, alarm))
            self.assertEqual(self.xeg_outputs(fd), do, "DO with alarm %d" % alarm)
            self.assertEqual(transact(fd, rtu("02 07"), 5), rtu("02 07 %02X" % fc07))
            self.assertEqual(self.fc10_exception(fd, 2, 0x0630, [3200, 8000, 1]), 0x04)
            self.assertEqual(self.control("device 2 clear"), "ok")
        self.assertEqual(self.xeg_state(fd)[1], 0)
        self.assertEqual(transact(fd, rtu("02 07"), 5), rtu("02 07 00"))
        self.assertTrue(self.control("device 2 alarm 9").startswith("error: "))

    # ---- EXCD203MB -------------------------------------------------------------------

    def excd_state(self, fd):
        rms, rabs_hi, rabs_lo, _rin, _rout, rby = self.read_regs(fd, 3, 0x03, 0x0200, 6)
        rabs = rabs_hi << 16 | rabs_lo
        return (rabs - (1 << 32) if rabs >= 1 << 31 else rabs), (rby, rms)

    def test_excd_moves_at_svr_and_shows_an_injected_alarm(self):
        self.start("--bus", self.path("line-a") + ":hiwin-xeg@2,excd203mb@3,wtec-ascii@5",
                   "--control", self.path("sim.sock"))
        fd = self.open_port("line-a")
        self.assertEqual(self.excd_state(fd), (0, (1, 0)))
        # svr = 8000 pulses/s, then abs to -6000: 0.75 s, rby 0 and rms 8000 meanwhile.
        self.fc10(fd, 3, 0x000F, [0, 8000])
        t_sent = time.monotonic()
        self.fc10(fd, 3, 0x0100, [0xFFFF, 0xE890])  # -6000
        t_acked = time.monotonic()
        samples = self.follow(lambda: self.excd_state(fd), lambda s: s.status[0] == 1)
        self.assertEqual(samples[-1].position, -6000)
        self.assertTrue(all(s.status == (0, 8000) for s in samples[:-1]), "busy at svr while moving")
        self.assertEqual(samples[-1].status, (1, 0))
        self.check_speed_line(samples, 0, -6000, 8000, t_sent, t_acked, "abs")
        # Injected alarm: ralarm (0x02D6) reads it, motion answers 04, stop still works.
        self.assertEqual(self.control("device 3 alarm 321"), "ok")
        self.assertEqual(self.read_regs(fd, 3, 0x03, 0x02D6, 1), [321])
        self.assertEqual(self.fc10_exception(fd, 3, 0x0100, [0, 0]), 0x04)
        self.fc10(fd, 3, 0x0108, [0])
        self.assertEqual(self.control("device 3 clear"), "ok")
        self.assertEqual(self.read_regs(fd, 3, 0x03, 0x02D6, 1), [0])
        # Home: back to 0 at hvr (2000 pulses/s by default), home sensor on at 0.
        t_sent = time.monotonic()
        self.fc10(fd, 3, 0x0107, [0])
        t_acked = time.monotonic()
        samples = self.follow(lambda: self.excd_state(fd), lambda s: s.status[0] == 1)
        self.assertEqual(samples[-1].position, 0)
        self.check_speed_line(samples, -6000, 0, 2000, t_sent, t_acked, "home")
        self.assertEqual(self.read_regs(fd, 3, 0x03, 0x0206, 1)[0] & 1, 1)

    # ---- WTEC-485 (ASCII) --------------------------------------------------------------

    def ascii(self, fd, body):
        os.write(fd, simlib.ascii_frame(body))
        reply = simlib.read_line(fd)
        self.assertTrue(reply.startswith(body[:4].encode()), "%s -> %r" % (body, reply))
        return reply[4:-6].decode()

    def test_wtec_homing_failure_grip_and_release(self):
        self.start("--bus", self.path("line-a") + ":hiwin-xeg@2,excd203mb@3,wtec-ascii@5",
                   "--control", self.path("sim.sock"))
        fd = self.open_port("line-a")
        self.assertEqual(self.ascii(fd, ">05g"), "00")    # not homed
        self.assertEqual(self.ascii(fd, ">05d"), "11")    # motor released
        # E before homing: the request comes back and nothing moves (manual, command 9).
        os.write(fd, simlib.ascii_frame(">05E1"))
        self.assertEqual(simlib.read_line(fd), simlib.ascii_frame(">05E1"))
        # An injected homing failure: g 02, cleared by "clear".
        self.assertEqual(self.control("device 5 fail-homing"), "ok")
        self.ascii(fd, ">05G")
        self.assertTrue(simlib.wait_until(lambda: self.ascii(fd, ">05g") == "02", MOTION_TIMEOUT))
        self.assertEqual(self.control("device 5 clear"), "ok")
        self.assertEqual(self.ascii(fd, ">05g"), "00")
        # Homing: 09 while it runs, then 01 and reached.
        self.ascii(fd, ">05G")
        self.assertEqual(self.ascii(fd, ">05g"), "09")
        self.assertTrue(simlib.wait_until(lambda: self.ascii(fd, ">05g") == "01", MOTION_TIMEOUT))
        self.assertEqual(self.ascii(fd, ">05d"), "01")
        # Grip an object 40 % of the opening wide: closing stops at 60 % of the stroke
        # (12000 counts of 20000) with state 02 and the grip current, which `C` sets as
        # the N max current (characters 8-9 of N; power-up 3F).
        self.assertEqual(self.ascii(fd, ">05N")[8:10], "3F")
        self.ascii(fd, ">05C3C")
        self.assertEqual(self.ascii(fd, ">05N")[8:10], "3C")
        self.assertEqual(self.control("device 5 object 40"), "ok")
        self.ascii(fd, ">05E1")
        self.assertTrue(simlib.wait_until(lambda: self.ascii(fd, ">05d") == "02", MOTION_TIMEOUT))
        self.assertEqual(self.ascii(fd, ">05I"), "%08X3C102" % 12000)
        # Release to the open limit: state 05 at -3 counts, the manual's I example.
        self.ascii(fd, ">05E2")
        self.assertTrue(simlib.wait_until(lambda: self.ascii(fd, ">05d") == "05", MOTION_TIMEOUT))
        self.assertEqual(self.ascii(fd, ">05I"), "FFFFFFFD03105")
        self.assertEqual(read_for(fd, 0.01), b"")


if __name__ == "__main__":
    simlib.main()
