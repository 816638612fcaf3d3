"""Modbus TCP through the real gateway to simulated serial devices (issue 4): the
HIWIN XEG quick start of manual 001 Appendix 1 driven with pymodbus and mbpoll, FC06
translated for the XEG, EXCD203MB 32-bit pairs, the WTEC ASCII uniform view against a
WTEC RTU gripper doing the same (also through e-stop -> initialise -> move, issue 13),
and a line's broadcast unit."""

import subprocess
import time

import gatewaylib

XEG, EXCD, WTEC_ASCII, WTEC_RTU, BROADCAST = 1, 2, 3, 4, 100
MOTION_TIMEOUT = 30.0  # homing 32 mm at 10 mm/s takes 3.2 s in the model

# XEG registers (docs/registers.md, seed 001 section 3)
XEG_MODEL, XEG_RESET, XEG_MOVE, XEG_EXPERT = 0x0600, 0x0610, 0x0630, 0x0640
XEG_POSITION, XEG_STATUS, XEG_FIRMWARE = 0x0300, 0x0301, 0x0303
IDLE, WORKING, POSITIONED = 0, 1, 2


def pair(value):
    """A 32-bit value as two registers, high word first (northbound order)."""
    value &= 0xFFFFFFFF
    return [value >> 16, value & 0xFFFF]


class XegQuickStart(gatewaylib.CellTestCase):

    def xeg_status(self, client):
        return self.read_input(client, XEG_STATUS, 1, XEG)[0]

    def home(self, client):
        # Wait for the position too: the status read at once may still be the image's
        # idle from before the reset (served while younger than max_age).
        self.assert_ok(client.write_registers(XEG_RESET, [1], slave=XEG))
        self.wait_value(lambda: self.read_input(client, XEG_POSITION, 2, XEG), [3200, IDLE], MOTION_TIMEOUT,
                        "XEG position and status after reset")

    def test_quick_start_through_the_gateway(self):
        """Manual 001 Appendix 1 with a default device config (no allow_protected):
        every write of the manual goes on the line as the manual's frame and is
        answered with the manual's reply. Status reads are served from the image the
        gateway polls (0x0300-0x0301 in one read), so their frames differ; their
        values are the manual's."""
        self.start_cell(sim_extra=("--log-level", "trace"))
        client = self.client()
        # 1-2: write the model XEG-32 (FC16), then 3-4: the gateway reads it back.
        self.assert_ok(client.write_registers(XEG_MODEL, [0x0A20], slave=XEG))
        self.assertEqual(self.read_holding(client, XEG_MODEL, 1, XEG), [0x0A20])
        # 5-6: firmware V3.0.1.884 (read at start).
        self.assertEqual(self.read_input(client, XEG_FIRMWARE, 4, XEG), [3, 0, 1, 884])
        # 7-13: reset, working, then idle at 32.00 mm. The manual reads "working" at
        # once; through the gateway a read in the first ~20 ms after the acknowledged
        # reset is served from the image, which still holds the idle status of before
        # (until the next motion poll): hence "until working", then "until idle".
        self.assert_ok(client.write_registers(XEG_RESET, [1], slave=XEG))
        self.wait_value(lambda: self.xeg_status(client), WORKING, MOTION_TIMEOUT, "XEG status after reset")
        self.wait_value(lambda: self.read_input(client, XEG_POSITION, 2, XEG), [3200, IDLE], MOTION_TIMEOUT,
                        "XEG position and status after reset")
        # 14-20: expert move 10 mm, hold 5 mm at force 100 %: idle at 17.00 mm.
        self.assert_ok(client.write_registers(XEG_EXPERT, [0, 1000, 8000, 500, 2000, 100, 1], slave=XEG))
        self.wait_value(lambda: self.read_input(client, XEG_POSITION, 2, XEG), [1700, IDLE],
                        MOTION_TIMEOUT, "XEG position and status after the expert move")
        # mbpoll reads the same position (input register 0x0300, 0-based references).
        out = subprocess.run(["mbpoll", "-m", "tcp", "-p", str(self.tcp_port), "-a", str(XEG), "-0", "-1",
                              "-o", "3", "-t", "3", "-r", str(XEG_POSITION), "127.0.0.1"],
                             capture_output=True, text=True, timeout=30)
        self.assertEqual(out.returncode, 0, out.stdout + out.stderr)
        self.assertIn("[%d]: \t1700" % XEG_POSITION, out.stdout)
        # 21-27: the move as a broadcast (the line's broadcast unit), then positioned
        # at 32.00 mm.
        self.assert_ok(client.write_registers(XEG_MOVE, [3200, 8000, 1], slave=BROADCAST))
        self.wait_value(lambda: self.read_input(client, XEG_POSITION, 2, XEG), [3200, POSITIONED],
                        MOTION_TIMEOUT, "XEG position and status after the broadcast move")
        # Frame for frame, in the manual's order (scenario numbers).
        trace = self.bus_trace("line-a")
        at = self.assert_exchange(trace, "02 04 03 03 00 04 01 BE",
                                  "02 04 08 00 03 00 00 00 01 03 74 49 5E")                   # 5-6
        at = self.assert_exchange(trace, "02 10 06 00 00 01 02 0A 20 D3 D8", "02 10 06 00 00 01 01 72")  # 1-2
        at = self.assert_exchange(trace, "02 03 06 00 00 01 84 B1", "02 03 02 0A 20 FB 3C", at)  # 3-4
        at = self.assert_exchange(trace, "02 10 06 10 00 01 02 00 01 17 F0", "02 10 06 10 00 01 00 B7",
                                  at)                                                             # 7-8
        at = self.assert_exchange(trace, "02 10 06 40 00 07 0E 00 00 03 E8 1F 40 01 F4 07 D0 00 64 00 01 E6 B8",
                                  "02 10 06 40 00 07 80 A4", at)                                  # 14-15
        self.assert_exchange(trace, "00 10 06 30 00 03 06 0C 80 1F 40 00 01 3C A4", None, at)   # 21-22

    def test_model_write_limits_and_new_ranges(self):
        """0x0600 takes the models of manual 001 section 3.3 only (0x03 locally, nothing
        sent); after XEG-16 is written, a 32 mm move is out of range at once."""
        self.start_cell(sim_extra=("--log-level", "trace"))
        client = self.client()
        self.assert_exception(client.write_registers(XEG_MODEL, [0x0A22], slave=XEG), 0x03)
        self.assert_exception(client.write_register(XEG_MODEL, 0x1234, slave=XEG), 0x03)
        model_writes = [f for f in self.bus_trace("line-a") if f[0] == "request" and f[1].startswith("02 10 06 00")]
        self.assertEqual(model_writes, [])
        # FC06 goes out as FC16 (the XEG has no FC06); the model is read back.
        self.assert_ok(client.write_register(XEG_MODEL, 0x0A10, slave=XEG))
        self.assert_exception(client.write_registers(XEG_MOVE, [3200, 6000, 1], slave=XEG), 0x03)
        # 16 mm is in range: it goes to the controller, which refuses it (0x04) only
        # because it has not been reset yet (manual 001 section 4.2.4, 0x07).
        self.assert_exception(client.write_registers(XEG_MOVE, [1600, 6000, 1], slave=XEG), 0x04)
        self.assertEqual(self.read_holding(client, XEG_MODEL, 1, XEG), [0x0A10])
        trace = self.bus_trace("line-a")
        at = self.assert_exchange(trace, "02 10 06 00 00 01 02 0A 10 D3 CC", "02 10 06 00 00 01 01 72")
        # The read-back goes out after the write's answer, and may follow the move the
        # client sent at once (a faster client, pymodbus 3.8, sends it sooner).
        read_back = ("request", "02 03 06 00 00 01 84 B1")
        self.wait_value(lambda: read_back in self.bus_trace("line-a")[at:], True, gatewaylib.IO_TIMEOUT,
                        "the model read back on line-a after its write")
        self.assert_exchange(self.bus_trace("line-a"), "02 03 06 00 00 01 84 B1", "02 03 02 0A 10 FB 28", at)

    def test_fc06_is_sent_as_fc16_and_answered_as_fc06(self):
        self.start_cell()
        client = self.client()
        self.home(client)
        before = self.sim_stats()["buses"]["line-a"]["devices"]["2"]
        # The XEG knows no FC06 (it would answer 0x01): an echo proves the translation.
        for address, value in ((XEG_MOVE, 1000), (XEG_MOVE + 1, 5000), (XEG_MOVE + 2, 1)):
            reply = self.assert_ok(client.write_register(address, value, slave=XEG))
            # The echoed value: .value in pymodbus 3.0 (Debian 12), .registers in 3.8 (13).
            echoed = reply.value if hasattr(reply, "value") else reply.registers[0]
            self.assertEqual((reply.function_code, reply.address, echoed), (0x06, address, value))
        self.wait_value(lambda: self.read_input(client, XEG_POSITION, 2, XEG), [1000, POSITIONED],
                        MOTION_TIMEOUT, "XEG position and status after the FC06 move")
        after = self.sim_stats()["buses"]["line-a"]["devices"]["2"]
        self.assertGreater(after["replies"], before["replies"])

    def test_mbpoll_writes_a_holding_register(self):
        self.start_cell()
        client = self.client()
        self.home(client)
        # mbpoll writes with FC06 for one value (-t 4 = holding, 16 bit).
        base = ["mbpoll", "-m", "tcp", "-p", str(self.tcp_port), "-a", str(XEG), "-0", "-1", "-o", "3", "-t", "4"]
        for address, value in ((XEG_MOVE, 2500), (XEG_MOVE + 1, 8000), (XEG_MOVE + 2, 1)):
            out = subprocess.run(base + ["-r", str(address), "127.0.0.1", str(value)],
                                 capture_output=True, text=True, timeout=30)
            self.assertEqual(out.returncode, 0, out.stdout + out.stderr)
        self.wait_value(lambda: self.read_input(client, XEG_POSITION, 2, XEG), [2500, POSITIONED],
                        MOTION_TIMEOUT, "XEG position and status after the mbpoll move")


class ExcdPairs(gatewaylib.CellTestCase):

    def test_32_bit_pairs(self):
        self.start_cell()
        client = self.client()
        # solm+ 0x0014 and solm- 0x0016 (signed pairs): whole pairs in one FC16 each.
        self.assert_ok(client.write_registers(0x0014, pair(100000), slave=EXCD))
        self.assert_ok(client.write_registers(0x0016, pair(-100000), slave=EXCD))
        self.assertEqual(self.read_holding(client, 0x0014, 4, EXCD), pair(100000) + pair(-100000))
        # Two pairs in one FC16 (svr 0x000F pair, div 0x0011 single).
        self.assert_ok(client.write_registers(0x000F, pair(2000) + [0x0C80], slave=EXCD))
        self.assertEqual(self.read_holding(client, 0x000F, 3, EXCD), pair(2000) + [0x0C80])
        # Half a pair: 0x02, and nothing changed.
        self.assert_exception(client.write_registers(0x0014, [7], slave=EXCD), 0x02)
        self.assert_exception(client.write_register(0x0015, 7, slave=EXCD), 0x02)
        self.assert_exception(client.write_registers(0x0015, [0, 7], slave=EXCD), 0x02)
        self.assertEqual(self.read_holding(client, 0x0014, 2, EXCD), pair(100000))
        # Reading half a pair is allowed.
        self.assertEqual(self.read_holding(client, 0x0015, 1, EXCD), [100000 & 0xFFFF])
        # An absolute move (0x0100 pair, signed) ends at rabs (0x0201 pair).
        self.assert_ok(client.write_registers(0x0100, pair(-1500), slave=EXCD))
        self.wait_value(lambda: self.read_holding(client, 0x0201, 2, EXCD), pair(-1500), MOTION_TIMEOUT,
                        "EXCD203MB rabs after abs -1500")
        # Out of the ±8,300,000 range: 0x03.
        self.assert_exception(client.write_registers(0x0100, pair(8300001), slave=EXCD), 0x03)


class WtecUniformView(gatewaylib.CellTestCase):
    """The same scenario on the WTEC ASCII gripper (unit 3, line-a) and the WTEC RTU
    gripper (unit 4, line-b) reads the same through the uniform register map."""

    def scenario(self, client, unit):
        self.assertEqual(client.write_register(0x0100, 1, slave=unit).isError(), False)
        self.wait_value(lambda: self.read_holding(client, 0x0200, 1, unit), [1], MOTION_TIMEOUT,
                        "init state of unit %d" % unit)
        self.assert_ok(client.write_register(0x0105, 50, slave=unit))
        self.wait_value(lambda: (self.read_holding(client, 0x0202, 1, unit)
                                 + self.read_holding(client, 0x0204, 1, unit)),
                        [1, 50], MOTION_TIMEOUT, "grip state and position of unit %d" % unit)
        # force and speed in one FC16 (ASCII: C then n; RTU: two FC06). The ASCII view
        # needs R and N read first (slow poll, 1 s): 0x0B until then. 40 % and 80 % read
        # back unchanged through the ASCII scaling (force over R's max current 0x3F: not
        # every percentage does, docs/registers.md "Scaling").
        def write_force_speed():
            return not client.write_registers(0x0103, [40, 80], slave=unit).isError()
        self.assertTrue(gatewaylib.simlib.wait_until(write_force_speed, 10.0, interval=0.2),
                        "force/speed write of unit %d never succeeded" % unit)
        self.wait_value(lambda: self.read_holding(client, 0x0103, 3, unit), [40, 80, 50], 5.0,
                        "force, speed, target of unit %d" % unit)
        return {
            "init": self.read_holding(client, 0x0200, 1, unit),
            "grip": self.read_holding(client, 0x0202, 1, unit),
            "position": self.read_holding(client, 0x0204, 1, unit),
            "params": self.read_holding(client, 0x0102, 4, unit),
            "direction": self.read_holding(client, 0x0300, 1, unit),
        }

    def test_ascii_and_rtu_read_the_same(self):
        self.start_cell()
        client = self.client()
        ascii_view = self.scenario(client, WTEC_ASCII)
        rtu_view = self.scenario(client, WTEC_RTU)
        self.assertEqual(ascii_view, rtu_view)
        self.assertEqual(ascii_view["params"], [0, 40, 80, 50])
        # Closing onto an object of 30 % grips it on both (grip state 2). The simulator
        # homes to the open end, so counts and percentages grow towards closed: the
        # jaws close by moving to 100 % and meet the object at 70 %.
        self.control("device line-a@5 object 30")
        self.control("device line-b@1 object 30")
        for unit in (WTEC_ASCII, WTEC_RTU):
            self.assert_ok(client.write_register(0x0105, 100, slave=unit))
        for unit in (WTEC_ASCII, WTEC_RTU):
            self.wait_value(lambda: self.read_holding(client, 0x0202, 1, unit), [2], MOTION_TIMEOUT,
                            "grip state of unit %d on the object" % unit)
        # 0x0202 and 0x0204 are polled by separate reads: the position may lag a poll.
        for unit in (WTEC_ASCII, WTEC_RTU):
            self.wait_value(lambda: self.read_holding(client, 0x0204, 1, unit), [70], 5.0,
                            "position of unit %d on the object" % unit)


class WtecEstopRecovery(gatewaylib.CellTestCase):
    """The RTU-mode procedure e-stop (0x0102 = 1) -> initialise (0x0100 = 1) -> move
    (0x0105 = 30) on the ASCII gripper (unit 3) and the RTU gripper (unit 4): the same
    0x0200 init state, 0x0202 grip state and 0x0204 position after each step."""

    def status(self, client, unit):
        return [self.read_holding(client, a, 1, unit)[0] for a in (0x0102, 0x0200, 0x0202, 0x0204)]

    def settle(self, client, expected, what):
        """Waits until both grippers read `expected` (e-stop, init, grip, position) and
        returns their readings, which must be equal."""
        views = {}
        for unit in (WTEC_ASCII, WTEC_RTU):
            self.wait_value(lambda: self.status(client, unit), expected, MOTION_TIMEOUT,
                            "0x0102, 0x0200, 0x0202, 0x0204 of unit %d %s" % (unit, what))
            views[unit] = self.status(client, unit)
        self.assertEqual(views[WTEC_ASCII], views[WTEC_RTU], what)
        return views[WTEC_ASCII]

    def step(self, client, address, value, expected, what):
        """Writes address = value on both grippers, then settle()s on `expected`."""
        for unit in (WTEC_ASCII, WTEC_RTU):
            self.assert_ok(client.write_register(address, value, slave=unit))
        return self.settle(client, expected, what)

    def test_estop_initialise_move_in_both_modes(self):
        self.start_cell()
        client = self.client()
        # Homed at the open end (direction 1): grip state 1 (reached) at 0 %.
        self.step(client, 0x0100, 1, [0, 1, 1, 0], "after the first initialise")
        self.step(client, 0x0105, 50, [0, 1, 1, 50], "at 50 %")
        # E-stop: latched, motor released (grip state 11), still homed, not moved.
        self.step(client, 0x0102, 1, [1, 1, 11, 50], "after the e-stop")
        # A move now is refused by the gripper (ASCII: `D` echoed back): 0x04 within
        # one transaction, well before the 300 ms response timeout, never 0x0B.
        for unit in (WTEC_ASCII, WTEC_RTU):
            started = time.monotonic()
            self.assert_exception(client.write_register(0x0105, 30, slave=unit), 0x04)
            self.assertLess(time.monotonic() - started, 0.3, "unit %d: a refusal, not a timeout" % unit)
        self.assertIn("did not execute `D`", self.gateway.text())
        self.settle(client, [1, 1, 11, 50], "after the refused move")
        # Initialise (ASCII: a1 then G) unlocks and homes both; then the move is done.
        self.step(client, 0x0100, 1, [0, 1, 1, 0], "after the initialise")
        self.step(client, 0x0105, 30, [0, 1, 1, 30], "after the move")
        # 0x0105 reads the target last sent in both modes, also after the ASCII view's
        # slow poll (N, 1 s) has come round twice (issue 24 item 5).
        time.sleep(2.2)
        for unit in (WTEC_ASCII, WTEC_RTU):
            self.assertEqual(self.read_holding(client, 0x0105, 1, unit), [30], "0x0105 of unit %d" % unit)


class BroadcastUnit(gatewaylib.CellTestCase):

    def test_broadcast_write_acts_on_the_devices(self):
        self.start_cell()
        client = self.client()
        self.assert_ok(client.write_registers(XEG_RESET, [1], slave=XEG))
        self.wait_value(lambda: self.read_input(client, XEG_POSITION, 2, XEG), [3200, IDLE], MOTION_TIMEOUT,
                        "XEG position and status after reset")
        frames_before = self.sim_stats()["buses"]["line-a"]["broadcasts"]
        # Quick start step 21: the move as a broadcast (address 0), answered at once.
        reply = self.assert_ok(client.write_registers(XEG_MOVE, [1200, 8000, 1], slave=BROADCAST))
        self.assertEqual((reply.address, reply.count), (XEG_MOVE, 3))
        self.wait_value(lambda: self.read_input(client, XEG_POSITION, 2, XEG), [1200, POSITIONED],
                        MOTION_TIMEOUT, "XEG after the broadcast move")
        # The EXCD203MB gets its own broadcast address 0xFF: solm+ reads back on unit 2.
        self.assert_ok(client.write_registers(0x0014, pair(4321), slave=BROADCAST))
        self.wait_value(lambda: self.read_holding(client, 0x0014, 2, EXCD), pair(4321), 10.0,
                        "EXCD203MB solm+ after the broadcast")
        self.assertGreaterEqual(self.sim_stats()["buses"]["line-a"]["broadcasts"], frames_before + 2)
        # Only writes can be broadcast.
        self.assert_exception(client.read_holding_registers(0x0014, count=2, slave=BROADCAST), 0x01)


if __name__ == "__main__":
    gatewaylib.main()
